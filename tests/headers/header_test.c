/*
 * header_test.c — compiled once per public header by tests/headers/meson.build
 * (as dav1d's tests/header_test.c): the header named by SM_TEST_HEADER is the
 * first thing in the translation unit, so it must include everything it uses,
 * and it is included twice, so its include guard must work.  Building is the
 * test; the program itself does nothing.
 */
#include SM_TEST_HEADER
#include SM_TEST_HEADER

int main(void)
{
    return 0;
}
