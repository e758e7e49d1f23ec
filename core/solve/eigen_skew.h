/*
 * eigen_skew.h — the Hermitian gyroscopic eigen-solves of eigen_skew.c, for eigen.c only
 * (complex.h defines I, which other core files use as a name).
 */
#ifndef SPINMODAL_EIGEN_SKEW_H
#define SPINMODAL_EIGEN_SKEW_H

#include <complex.h>

/* The Hermitian gyroscopic problem of eig_solve (eigen_skew.c): the k lowest frequencies w
 * (ascending) and vectors Y (ld 2r) of -i S, S = [[0, B], [-B', -G]] (direct form), or of its
 * inverse i E, E = [[-F, -D'], [D, 0]] (inverse form), all r x r.  The *_lowest routes return
 * SM_LAPACK_FAILED when the caller should fall back to the *_zheevr ones; fixed_bits (the
 * kind's, kind.h) chooses dm_syev_range's route.  SM_OK, SM_NOMEM, SM_LAPACK_FAILED. */
int eig_dir_lowest(int fixed_bits, int r, const double *B, const double *G, int k, double *w,
                   double complex *Y);
int eig_dir_zheevr(int r, const double *B, const double *G, int k, double *w, double complex *Y);
int eig_skew_lowest(int fixed_bits, int r, const double *D, const double *F, int k, double *w,
                    double complex *Y);
int eig_skew_zheevr(int r, const double *D, const double *F, int k, double *w, double complex *Y);

#endif /* SPINMODAL_EIGEN_SKEW_H */
