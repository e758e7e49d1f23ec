/*
 * fortran_rt.c — the one routine of the GNU Fortran runtime that OpenBLAS's LAPACK calls, so that
 * the two programs start without libgfortran (issue 27 goal 1, DESIGN.md §2.1).
 *
 * LAPACK is Fortran; linked from OpenBLAS's archive (server/meson.build), the only symbol its
 * objects take from libgfortran is _gfortran_concat_string, the `//` of two strings (ilaenv's
 * OPTS argument, SIDE // TRANS in dormtr and its kin).  Loading libgfortran for it brings
 * libquadmath and libgcc_s, and their constructors ask the CPU what it supports with the CPUID
 * instruction, which a virtual machine traps: 8 us an instruction here, 0.3-0.5 ms of every
 * process start in all.  This file defines the routine (libgfortran/intrinsics/
 * string_intrinsics_inc.c, concat_string, for CHARACTER(KIND=1): the character length type is
 * size_t since GCC 8, the GFORTRAN_8 version of the symbol); with --as-needed (meson's default)
 * the link then names libgfortran only when the archive needs anything else from it, and then
 * this definition takes precedence over libgfortran's, with the same behaviour
 * (tests/server/test_fortran_rt.c compares the two).
 */
#include <stddef.h>
#include <string.h>

/* dest (destlen) = s1 (len1) // s2 (len2), cut to destlen or padded with blanks: Fortran's
 * assignment of a concatenation to a CHARACTER(destlen) variable.  The name and ABI are
 * libgfortran's. */
void _gfortran_concat_string(size_t destlen, char *dest, size_t len1, const char *s1, size_t len2,
                             const char *s2);

void _gfortran_concat_string(size_t destlen, char *dest, size_t len1, const char *s1, size_t len2,
                             const char *s2)
{
    if (len1 >= destlen) {
        memcpy(dest, s1, destlen);
        return;
    }
    memcpy(dest, s1, len1);
    dest += len1;
    destlen -= len1;
    if (len2 >= destlen) {
        memcpy(dest, s2, destlen);
        return;
    }
    memcpy(dest, s2, len2);
    memset(dest + len2, ' ', destlen - len2);
}
