/*
 * test_fortran_rt.c — server/fortran_rt.c's _gfortran_concat_string against libgfortran's own
 * (dlopen'ed: the symbol of that library, not the one this program defines), on every split of
 * destination, first and second lengths from 0 to 12: the same bytes, the tail beyond the
 * destination untouched.  Then that a LAPACK routine which concatenates (dormtr: SIDE // TRANS
 * for ilaenv) still works when linked with it: Q' (Q x) = x for Q from dsytrd.
 */
#include <dlfcn.h>
#include <lapacke.h>
#include <stdio.h>
#include <string.h>

typedef void concat_fn(size_t, char *, size_t, const char *, size_t, const char *);
void _gfortran_concat_string(size_t destlen, char *dest, size_t len1, const char *s1, size_t len2,
                             const char *s2);

static int failures, checks;

#define CHECK(cond, ...)         \
    do {                         \
        checks++;                \
        if (!(cond)) {           \
            failures++;          \
            printf("FAIL ");     \
            printf(__VA_ARGS__); \
            printf("\n");        \
        }                        \
    } while (0)

static void against_libgfortran(void)
{
    void *h = dlopen("libgfortran.so.5", RTLD_NOW | RTLD_LOCAL);
    CHECK(h, "libgfortran.so.5 loads (%s): deploy/install-deps.sh installs it", h ? "" : dlerror());
    if (!h)
        return;
    concat_fn *ref = NULL;
    *(void **)&ref = dlsym(h, "_gfortran_concat_string"); /* POSIX's way to a function pointer */
    CHECK(ref && ref != _gfortran_concat_string, "libgfortran's own _gfortran_concat_string found");
    if (!ref || ref == _gfortran_concat_string) {
        dlclose(h);
        return;
    }
    const char *s1 = "ABCDEFGHIJKL", *s2 = "mnopqrstuvwx";
    int cases = 0;
    for (size_t d = 0; d <= 12; d++)
        for (size_t a = 0; a <= 12; a++)
            for (size_t b = 0; b <= 12; b++) {
                char x[32], y[32];
                memset(x, '#', sizeof x);
                memset(y, '#', sizeof y);
                _gfortran_concat_string(d, x, a, s1, b, s2);
                ref(d, y, a, s1, b, s2);
                CHECK(memcmp(x, y, sizeof x) == 0,
                      "dest %zu, lengths %zu and %zu: %.20s against %.20s", d, a, b, x, y);
                cases++;
            }
    printf("%d length combinations against libgfortran's routine\n", cases);
    dlclose(h);
}

static void through_lapack(void)
{
    enum { N = 6 };
    double A[N * N], d[N], e[N], tau[N], x[N], y[N];
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++)
            A[j * N + i] = 1.0 / (1 + i + j) + (i == j);
    for (int i = 0; i < N; i++)
        x[i] = y[i] = 1 + i;
    CHECK(LAPACKE_dsytrd(LAPACK_COL_MAJOR, 'L', N, A, N, d, e, tau) == 0, "dsytrd");
    CHECK(LAPACKE_dormtr(LAPACK_COL_MAJOR, 'L', 'L', 'N', N, 1, A, N, tau, y, N) == 0,
          "dormtr Q x");
    CHECK(LAPACKE_dormtr(LAPACK_COL_MAJOR, 'L', 'L', 'T', N, 1, A, N, tau, y, N) == 0,
          "dormtr Q' y");
    double err = 0;
    for (int i = 0; i < N; i++)
        err = err > (y[i] - x[i]) * (y[i] - x[i]) ? err : (y[i] - x[i]) * (y[i] - x[i]);
    CHECK(err < 1e-26, "Q' Q x = x (squared error %.2e)", err);
}

int main(void)
{
    against_libgfortran();
    through_lapack();
    printf("fortran_rt: %d checks, %d failures\n", checks, failures);
    return failures ? 1 : 0;
}
