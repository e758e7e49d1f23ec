/*
 * eigen_skew.c — the Hermitian gyroscopic eigenproblem of eigen.c in its two forms (DESIGN.md
 * 1.4): the direct form -i S, S = [[0, B], [-B', -G]] real skew, and the inverse form
 * i E = (-i S)^-1, E = [[-F, -D'], [D, 0]].  Each has a fast route (the real symmetric square
 * S'S or E'E by dm_syev_range: dsyevr for a kind with fixed_bits; complex candidates, a
 * Rayleigh-Ritz step) and a zheevr fallback.
 * eigen.c condenses the problem, builds B, G or D, F, and picks the form per mode.
 */
#include "internal.h"
#include "eigen_skew.h"

#include <cblas.h>
#include <complex.h>
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Directions added to the k requested in the Rayleigh-Ritz basis of the inverse-form solve. */
#define EIG_GUARD 4

/*
 * The candidate column acc of (Yr, Yi) (ld N2, complex y = yr + i yi) orthonormalised (twice)
 * against the acc accepted ones.  Returns 1 when it is kept (normalised), 0 when little of it
 * is left: the other half of an accepted pair.
 */
static int eig_skew_accept(int N2, int acc, double *Yr, double *Yi)
{
    double *yr = Yr + (size_t)acc * N2, *yi = Yi + (size_t)acc * N2, nrm = 0;
    for (int i = 0; i < N2; i++)
        nrm += yr[i] * yr[i] + yi[i] * yi[i];
    double nrm0 = sqrt(nrm);
    for (int pass = 0; pass < 2; pass++)
        for (int a = 0; a < acc; a++) {
            const double *ur = Yr + (size_t)a * N2, *ui = Yi + (size_t)a * N2;
            double cr = 0, ci = 0; /* c = u* y */
            for (int i = 0; i < N2; i++) {
                cr += ur[i] * yr[i] + ui[i] * yi[i];
                ci += ur[i] * yi[i] - ui[i] * yr[i];
            }
            for (int i = 0; i < N2; i++) {
                yr[i] -= cr * ur[i] - ci * ui[i];
                yi[i] -= cr * ui[i] + ci * ur[i];
            }
        }
    nrm = 0;
    for (int i = 0; i < N2; i++)
        nrm += yr[i] * yr[i] + yi[i] * yi[i];
    nrm = sqrt(nrm);
    if (nrm < 0.25 * nrm0)
        return 0;
    for (int i = 0; i < N2; i++) {
        yr[i] /= nrm;
        yi[i] /= nrm;
    }
    return 1;
}

/* y = S x for S = [[0, B], [-B', -G]] (2r x 2r, real skew) and the real
 * 2r x m block x (leading dimension 2r). */
static void eig_dir_apply(int r, const double *B, const double *G, int m, const double *x, double *y)
{
    int N2 = 2 * r;
    /* top = B x2;  bottom = -B' x1 - G x2 */
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, r, m, r, 1.0, B, r, x + r, N2, 0.0, y, N2);
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, r, m, r, -1.0, B, r, x, N2, 0.0, y + r, N2);
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, r, m, r, -1.0, G, r, x + r, N2, 1.0, y + r, N2);
}

/*
 * The direct form (the route of the frequencies far above the lowest, eig_gyro_hermitian).
 * The k lowest positive eigenpairs of the Hermitian matrix -i S, S real
 * skew (above), without complex arithmetic on the 2r-sized problem:
 * S'S = -S^2 = [[B B', B G], [-G B', B'B + G'G]] is real symmetric with the
 * eigenvalues w^2, each twice.  dm_syev_range gives the 2k lowest; each real
 * eigenvector v yields y = v - i S v / w with S y = i w y; the candidates are
 * orthonormalised (a pair gives one direction) and a Rayleigh-Ritz step on
 * -i S restores full accuracy (the squared problem alone loses digits of the
 * low frequencies to the high ones) and separates close frequencies.  About a
 * quarter of the floating-point work of zheevr on -i S.  Returns SM_OK, or
 * SM_LAPACK_FAILED when the caller should fall back to zheevr.
 */
int eig_dir_lowest(int fixed_bits, int r, const double *B, const double *G, int k, double *w,
                   double complex *Y)
{
    int N2 = 2 * r, m2 = 2 * k < N2 ? 2 * k : N2, acc = 0, rc = SM_NOMEM;
    double *A = dm_vec((size_t)N2 * N2), *ev = dm_vec((size_t)N2), *V = dm_vec((size_t)N2 * m2);
    double *SV = dm_vec((size_t)N2 * m2), *Yr = dm_vec((size_t)N2 * k), *Yi = dm_vec((size_t)N2 * k);
    double *SYr = dm_vec((size_t)N2 * k), *SYi = dm_vec((size_t)N2 * k), *th = dm_vec((size_t)k);
    double complex *T = calloc((size_t)k * k, sizeof(double complex));
    double complex *SY = calloc((size_t)N2 * k, sizeof(double complex));
    double complex *Q = calloc((size_t)N2 * k, sizeof(double complex));
    if (!A || !ev || !V || !SV || !Yr || !Yi || !SYr || !SYi || !th || !T || !SY || !Q)
        goto done;
    /* lower triangle of S'S */
    cblas_dsyrk(CblasColMajor, CblasLower, CblasNoTrans, r, r, 1.0, B, r, 0.0, A, N2);
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasTrans, r, r, r, -1.0, G, r, B, r, 0.0, A + r, N2);
    cblas_dsyrk(CblasColMajor, CblasLower, CblasTrans, r, r, 1.0, B, r, 0.0, A + (size_t)r * N2 + r, N2);
    cblas_dsyrk(CblasColMajor, CblasLower, CblasTrans, r, r, 1.0, G, r, 1.0, A + (size_t)r * N2 + r, N2);
    rc = dm_lapack_status(dm_syev_range(fixed_bits, N2, A, 1, m2, ev, V, N2), SM_LAPACK_FAILED);
    if (rc < 0)
        goto done;
    rc = SM_LAPACK_FAILED; /* from here on: the caller falls back to zheevr */
    eig_dir_apply(r, B, G, m2, V, SV);
    /* candidates y = v - i S v / w, orthonormalised (twice) against the accepted ones */
    for (int j = 0; j < m2 && acc < k; j++) {
        if (!(ev[j] > 1e-14 * ev[m2 - 1]))
            goto done;
        double wj = sqrt(ev[j]);
        for (int i = 0; i < N2; i++) {
            Yr[(size_t)acc * N2 + i] = V[(size_t)j * N2 + i];
            Yi[(size_t)acc * N2 + i] = -SV[(size_t)j * N2 + i] / wj;
        }
        acc += eig_skew_accept(N2, acc, Yr, Yi);
    }
    if (acc < k)
        goto done;
    /* Rayleigh-Ritz: T = Y* (-i S) Y, Y <- Y Q */
    eig_dir_apply(r, B, G, k, Yr, SYr);
    eig_dir_apply(r, B, G, k, Yi, SYi);
    for (size_t i = 0; i < (size_t)N2 * k; i++) {
        Q[i] = Yr[i] + I * Yi[i];
        SY[i] = -I * (SYr[i] + I * SYi[i]);
    }
    const double complex one = 1, zero = 0;
    cblas_zgemm(CblasColMajor, CblasConjTrans, CblasNoTrans, k, k, N2, &one, Q, N2, SY, N2, &zero, T, k);
    rc = dm_lapack_status(LAPACKE_zheev(LAPACK_COL_MAJOR, 'V', 'L', k, T, k, th), SM_LAPACK_FAILED);
    if (rc == SM_OK && !(th[0] > 0))
        rc = SM_LAPACK_FAILED;
    if (rc < 0)
        goto done;
    cblas_zgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, N2, k, k, &one, Q, N2, T, k, &zero, Y, N2);
    memcpy(w, th, (size_t)k * sizeof(double));
    rc = SM_OK;
done:
    free(A);
    free(ev);
    free(V);
    free(SV);
    free(Yr);
    free(Yi);
    free(SYr);
    free(SYi);
    free(th);
    free(T);
    free(SY);
    free(Q);
    return rc;
}

/* The k lowest positive eigenpairs of -i S by zheevr (the fallback). */
int eig_dir_zheevr(int r, const double *B, const double *G, int k, double *w, double complex *Y)
{
    int N2 = 2 * r, found = 0, rc = SM_NOMEM;
    double complex *H = calloc((size_t)N2 * N2, sizeof(double complex));
    double *wall = dm_vec((size_t)N2);
    int *sup = malloc(2 * (size_t)k * sizeof(int));
    if (!H || !wall || !sup)
        goto done;
    /* -i S, lower triangle: [[0, -iB], [iB', iG]] */
    for (int j = 0; j < r; j++)
        for (int i = 0; i < r; i++) {
            H[(size_t)j * N2 + (r + i)] = I * B[(size_t)i * r + j];          /* (r+i, j) = i B'(i,j) */
            if (i >= j)
                H[(size_t)(r + j) * N2 + (r + i)] = I * G[(size_t)j * r + i]; /* (r+i, r+j) */
        }
    rc = dm_lapack_status(LAPACKE_zheevr(LAPACK_COL_MAJOR, 'V', 'I', 'L', N2, H, N2, 0, 0, r + 1, r + k, 0.0,
                                         &found, wall, Y, N2, sup),
                          SM_LAPACK_FAILED);
    if (rc == SM_OK && found != k)
        rc = SM_LAPACK_FAILED;
    if (rc < 0)
        goto done;
    memcpy(w, wall, (size_t)k * sizeof(double));
    rc = SM_OK;
done:
    free(H);
    free(wall);
    free(sup);
    return rc;
}

/*
 * The gyroscopic problem is solved in the inverse of the real skew form of the header,
 *   S = [[0, B], [-B', -G]],  B = L' U^-1,  G = U^-T C_yy U^-1:
 *   E = S^-1 = [[-F, -D'], [D, 0]],  D = B^-1 = U L^-T,  F = D' G D = L^-1 C_yy L^-T (skew).
 * S y = i w y  <=>  i E y = (1/w) y: the lowest frequencies are the largest eigenvalues of the
 * Hermitian i E and are resolved relative to themselves, as in eig_undamped_inverse (at rest,
 * F = 0 and E'E = diag(D'D, D D'), D'D = L^-1 M_yy L^-T: that very matrix).  The form S
 * resolves w^2 only to eps w_max^2: a near-inextensible blade (EA = 1e14, w_max^2 ~ 1e16 at 64
 * elements) lost its first frequency to 6e-3 (DESIGN.md 9.4).
 */

/* y = E x for E = [[-F, -D'], [D, 0]] (2r x 2r, real skew) and the real 2r x m block x
 * (leading dimension 2r). */
static void eig_inv_apply(int r, const double *D, const double *F, int m, const double *x, double *y)
{
    int N2 = 2 * r;
    /* top = -F x1 - D' x2;  bottom = D x1 */
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, r, m, r, -1.0, F, r, x, N2, 0.0, y, N2);
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, r, m, r, -1.0, D, r, x + r, N2, 1.0, y, N2);
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, r, m, r, 1.0, D, r, x, N2, 0.0, y + r, N2);
}

/* The first k columns of Q (ld 2r, kk columns) T (kk x kk) in reverse order into Y (ld 2r):
 * ascending 1/w from zheev become ascending w. */
static void eig_inv_reverse(int N2, int kk, int k, const double complex *Q, const double complex *T,
                            double complex *Y)
{
    for (int j = 0; j < k; j++) {
        const double complex *t = T + (size_t)(kk - 1 - j) * kk;
        double complex *y = Y + (size_t)j * N2;
        for (int i = 0; i < N2; i++)
            y[i] = 0;
        for (int p = 0; p < kk; p++)
            for (int i = 0; i < N2; i++)
                y[i] += Q[(size_t)p * N2 + i] * t[p];
    }
}

/* Lower triangle of E'E = -E^2 = [[F'F + D'D, -F D'], [D F, D D']] into A (ld 2r); real
 * symmetric with the eigenvalues 1/w^2, each twice. */
static void eig_inv_square(int r, const double *D, const double *F, double *A)
{
    int N2 = 2 * r;
    cblas_dsyrk(CblasColMajor, CblasLower, CblasTrans, r, r, 1.0, F, r, 0.0, A, N2);
    cblas_dsyrk(CblasColMajor, CblasLower, CblasTrans, r, r, 1.0, D, r, 1.0, A, N2);
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, r, r, r, 1.0, D, r, F, r, 0.0, A + r, N2);
    cblas_dsyrk(CblasColMajor, CblasLower, CblasNoTrans, r, r, 1.0, D, r, 0.0, A + (size_t)r * N2 + r, N2);
}

/*
 * The k lowest frequencies w (ascending) and the vectors y (S y = i w y) of the Hermitian
 * i E = (-i S)^-1, without complex arithmetic on the 2r-sized problem: dm_syev_range gives the 2k
 * largest eigenvalues 1/w^2 of E'E; each real eigenvector v yields y = v + i w E v with
 * i E y = y / w; the candidates are orthonormalised (a pair gives one direction) and a
 * Rayleigh-Ritz step on i E restores full accuracy (the squared problem alone loses digits of a
 * frequency to the lowest one) and separates close frequencies.  About a quarter of the
 * floating-point work of zheevr on i E.  Returns SM_OK, or SM_LAPACK_FAILED when the caller
 * should fall back to zheevr.
 */
int eig_skew_lowest(int fixed_bits, int r, const double *D, const double *F, int k, double *w,
                    double complex *Y)
{
    /* kk = k + EIG_GUARD directions: a frequency just above the k-th (a close pair at the end
     * of the request) is then separated by the Rayleigh-Ritz step, not left out of the basis */
    int kk = k + EIG_GUARD < r ? k + EIG_GUARD : r, N2 = 2 * r, m2 = 2 * kk, acc = 0, rc = SM_NOMEM;
    double *A = dm_vec((size_t)N2 * N2), *ev = dm_vec((size_t)N2), *V = dm_vec((size_t)N2 * m2);
    double *EV = dm_vec((size_t)N2 * m2), *Yr = dm_vec((size_t)N2 * kk), *Yi = dm_vec((size_t)N2 * kk);
    double *EYr = dm_vec((size_t)N2 * kk), *EYi = dm_vec((size_t)N2 * kk), *th = dm_vec((size_t)kk);
    double complex *T = calloc((size_t)kk * kk, sizeof(double complex));
    double complex *EY = calloc((size_t)N2 * kk, sizeof(double complex));
    double complex *Q = calloc((size_t)N2 * kk, sizeof(double complex));
    if (!A || !ev || !V || !EV || !Yr || !Yi || !EYr || !EYi || !th || !T || !EY || !Q)
        goto done;
    eig_inv_square(r, D, F, A);
    rc = dm_lapack_status(dm_syev_range(fixed_bits, N2, A, N2 - m2 + 1, N2, ev, V, N2),
                          SM_LAPACK_FAILED);
    if (rc < 0)
        goto done;
    rc = SM_LAPACK_FAILED; /* from here on: the caller falls back to zheevr */
    eig_inv_apply(r, D, F, m2, V, EV);
    /* candidates y = v + i E v / mu (mu = 1/w), largest mu first, orthonormalised (twice)
     * against the accepted ones */
    for (int j = m2 - 1; j >= 0 && acc < kk; j--) {
        if (!(ev[j] > 1e-14 * ev[m2 - 1]))
            goto done;
        double mu = sqrt(ev[j]);
        for (int i = 0; i < N2; i++) {
            Yr[(size_t)acc * N2 + i] = V[(size_t)j * N2 + i];
            Yi[(size_t)acc * N2 + i] = EV[(size_t)j * N2 + i] / mu;
        }
        acc += eig_skew_accept(N2, acc, Yr, Yi);
    }
    if (acc < kk)
        goto done;
    /* Rayleigh-Ritz: T = Y* (i E) Y, Y <- Y Q */
    eig_inv_apply(r, D, F, kk, Yr, EYr);
    eig_inv_apply(r, D, F, kk, Yi, EYi);
    for (size_t i = 0; i < (size_t)N2 * kk; i++) {
        Q[i] = Yr[i] + I * Yi[i];
        EY[i] = I * (EYr[i] + I * EYi[i]);
    }
    const double complex one = 1, zero = 0;
    cblas_zgemm(CblasColMajor, CblasConjTrans, CblasNoTrans, kk, kk, N2, &one, Q, N2, EY, N2, &zero, T, kk);
    rc = dm_lapack_status(LAPACKE_zheev(LAPACK_COL_MAJOR, 'V', 'L', kk, T, kk, th), SM_LAPACK_FAILED);
    if (rc == SM_OK && !(th[0] > 0))
        rc = SM_LAPACK_FAILED;
    if (rc < 0)
        goto done;
    eig_inv_reverse(N2, kk, k, Q, T, Y);
    for (int j = 0; j < k; j++)
        w[j] = 1.0 / th[kk - 1 - j];
    rc = SM_OK;
done:
    free(A);
    free(ev);
    free(V);
    free(EV);
    free(Yr);
    free(Yi);
    free(EYr);
    free(EYi);
    free(th);
    free(T);
    free(EY);
    free(Q);
    return rc;
}

/* The k lowest frequencies and vectors of i E by zheevr (the fallback). */
int eig_skew_zheevr(int r, const double *D, const double *F, int k, double *w, double complex *Y)
{
    int N2 = 2 * r, found = 0, rc = SM_NOMEM;
    double complex *H = calloc((size_t)N2 * N2, sizeof(double complex));
    double complex *Z = calloc((size_t)N2 * k, sizeof(double complex));
    double *wall = dm_vec((size_t)N2);
    int *sup = malloc(2 * (size_t)k * sizeof(int));
    if (!H || !Z || !wall || !sup)
        goto done;
    /* i E, lower triangle: [[-i F, .], [i D, 0]] */
    for (int j = 0; j < r; j++)
        for (int i = 0; i < r; i++) {
            H[(size_t)j * N2 + (r + i)] = I * D[(size_t)j * r + i]; /* (r+i, j) = i D(i,j) */
            if (i >= j)
                H[(size_t)j * N2 + i] = -I * F[(size_t)j * r + i];  /* (i, j) = -i F(i,j) */
        }
    rc = dm_lapack_status(LAPACKE_zheevr(LAPACK_COL_MAJOR, 'V', 'I', 'L', N2, H, N2, 0, 0, N2 - k + 1, N2, 0.0,
                                         &found, wall, Z, N2, sup),
                          SM_LAPACK_FAILED);
    if (rc == SM_OK && (found != k || !(wall[0] > 0)))
        rc = SM_LAPACK_FAILED;
    if (rc < 0)
        goto done;
    for (int j = 0; j < k; j++) { /* ascending 1/w: descending w */
        w[j] = 1.0 / wall[k - 1 - j];
        memcpy(Y + (size_t)j * N2, Z + (size_t)(k - 1 - j) * N2, (size_t)N2 * sizeof(double complex));
    }
    rc = SM_OK;
done:
    free(H);
    free(Z);
    free(wall);
    free(sup);
    return rc;
}
