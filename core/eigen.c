/*
 * eigen.c — the eigen-analysis of the linearised equations (DESIGN.md 1.4):
 *
 *   coriolis on:   (lambda^2 M + lambda C + K) x = 0
 *   coriolis off:  K x = w^2 M x
 *
 * M may be singular (lumped mass + augmented basis: RF-1 massless
 * directions).  A pivoted Cholesky of M splits the coordinates into a range
 * part Y (the pivots) and an exact null space Z = P [-U11^-1 U12; I]; C Z = 0
 * there, so the Z rows give K_zy a + K_zz b = 0 and the problem condenses to
 *   K_red = K_yy - K_yz K_zz^-1 K_zy,   M_yy = U11' U11,   C_yy.
 * With K_red positive definite (K_red = L L') the gyroscopic problem is the
 * Hermitian eigenproblem of size 2r of  -i H,  H = [[0, B], [-B', -G]],
 * B = L' U11^-1, G = U11^-T C_yy U11^-1 (skew): exactly real frequencies.
 * It is solved in the inverse form i H^-1 (eigenvalues 1/w), which resolves
 * the lowest frequencies relative to themselves, as the undamped path does
 * with L^-1 M L^-T; modes far above the lowest (w^2 > w_1 w_max) come from
 * -i H itself.  Otherwise the companion form goes to dgeev.
 */
#include "internal.h"

#include <cblas.h>
#include <complex.h>
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

void eig_out_free(sm_eig_out *o)
{
    free(o->wre);
    free(o->wim);
    free(o->xre);
    free(o->xim);
    memset(o, 0, sizeof *o);
}

/*
 * *neg = number of negative eigenvalues of the symmetric matrix A (n x n,
 * destroyed), from the Bunch-Kaufman factorisation (Sylvester's law of
 * inertia).  A zero pivot (dsytrf info > 0) still completes the factorisation
 * and counts as non-negative.  Returns SM_OK, SM_NOMEM or SM_LAPACK_FAILED.
 */
static int eig_inertia(int n, double *A, int *neg_out)
{
    *neg_out = 0;
    if (n == 0)
        return SM_OK;
    int *ipiv = malloc((size_t)n * sizeof(int)), neg = 0;
    if (!ipiv)
        return SM_NOMEM;
    int rc = dm_lapack_status(LAPACKE_dsytrf(LAPACK_COL_MAJOR, 'L', n, A, n, ipiv), SM_OK);
    if (rc < 0) {
        free(ipiv);
        return rc;
    }
    for (int k = 0; k < n; k++) {
        double a = A[(size_t)k * n + k];
        if (ipiv[k] > 0 || k + 1 == n) {
            neg += a < 0;
        } else {
            double b = A[(size_t)k * n + k + 1], c = A[(size_t)(k + 1) * n + k + 1];
            double det = a * c - b * b;
            neg += det < 0 ? 1 : (a < 0 ? 2 : 0);
            k++;
        }
    }
    free(ipiv);
    *neg_out = neg;
    return SM_OK;
}

/* *neg = negative eigenvalue count of symmetric A; *chol receives 1 and the
 * lower Cholesky factor in L when A is positive definite (then *neg = 0).
 * Returns SM_OK, SM_NOMEM or SM_LAPACK_FAILED. */
static int eig_definite(int n, const double *A, double *L, int *chol, int *neg)
{
    memcpy(L, A, (size_t)n * n * sizeof(double));
    *neg = 0;
    *chol = 1;
    int rc = n == 0 ? SM_OK : dm_lapack_status(LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'L', n, L, n), SM_SINGULAR);
    if (rc != SM_SINGULAR) /* SM_OK, or dpotrf itself failed */
        return rc;
    *chol = 0; /* not positive definite: count the negative eigenvalues */
    memcpy(L, A, (size_t)n * n * sizeof(double));
    return eig_inertia(n, L, neg);
}

/* Directions added to the k requested in the Rayleigh-Ritz basis of the gyroscopic solve. */
#define EIG_GUARD 4

typedef struct eig_split {
    int r, z;        /* range and null dimensions */
    int *yi, *zi;    /* coordinate indices */
    double *U;       /* r x r upper Cholesky factor of M_yy */
    double *Z;       /* n x z null-space basis */
    double *S;       /* z x r: K_zz^-1 K_zy  (b = -S a) */
    double *Kr;      /* r x r condensed stiffness */
    int neg_zz;      /* negative eigenvalues of K_zz */
} eig_split;

static void eig_split_free(eig_split *sp)
{
    free(sp->yi);
    free(sp->zi);
    free(sp->U);
    free(sp->Z);
    free(sp->S);
    free(sp->Kr);
}

/* Pivoted Cholesky of M, null space, condensation of K on it.  Returns SM_OK,
 * SM_NOMEM, SM_SINGULAR (M has no range at all, or K_zz is exactly singular)
 * or SM_LAPACK_FAILED.  sp is filled even on failure (eig_split_free). */
static int eig_condense(int n, const dmat *M, const dmat *K, eig_split *sp)
{
    int rc = SM_NOMEM, rank = 0;
    double *W = dm_vec((size_t)n * n), *KZ = NULL, *Kzz = NULL, *Lzz = NULL;
    int *piv = malloc((size_t)n * sizeof(int));
    memset(sp, 0, sizeof *sp);
    if (!W || !piv)
        goto done;
    memcpy(W, M->a, (size_t)n * n * sizeof(double));
    double dmax = 0;
    for (int i = 0; i < n; i++)
        dmax = fmax(dmax, DM(M, i, i));
    /* info > 0 only says M is rank deficient: expected (massless directions) */
    rc = dm_lapack_status(LAPACKE_dpstrf(LAPACK_COL_MAJOR, 'U', n, W, n, piv, &rank, 1e-10 * dmax), SM_OK);
    if (rc < 0)
        goto done;
    rc = SM_SINGULAR; /* no mass at all */
    if (rank < 1)
        goto done;
    int r = rank, z = n - r;
    sp->r = r;
    sp->z = z;
    rc = SM_NOMEM;
    sp->yi = malloc((size_t)r * sizeof(int));
    sp->zi = malloc((size_t)(z ? z : 1) * sizeof(int));
    sp->U = dm_vec((size_t)r * r);
    sp->Z = dm_vec((size_t)n * z);
    sp->S = dm_vec((size_t)z * r);
    sp->Kr = dm_vec((size_t)r * r);
    KZ = dm_vec((size_t)n * z);
    Kzz = dm_vec((size_t)z * z);
    Lzz = dm_vec((size_t)z * z);
    if (!sp->yi || !sp->zi || !sp->U || !sp->Z || !sp->S || !sp->Kr || !KZ || !Kzz || !Lzz)
        goto done;
    for (int i = 0; i < r; i++)
        sp->yi[i] = piv[i] - 1;
    for (int j = 0; j < z; j++)
        sp->zi[j] = piv[r + j] - 1;
    for (int j = 0; j < r; j++)
        for (int i = 0; i <= j; i++)
            sp->U[(size_t)j * r + i] = W[(size_t)j * n + i];
    for (int i = 0; i < r; i++)
        for (int j = 0; j < r; j++)
            sp->Kr[(size_t)j * r + i] = DM(K, sp->yi[i], sp->yi[j]);
    if (z > 0) {
        /* Z = P [-U11^-1 U12; I] */
        double *T = dm_vec((size_t)r * z);
        if (!T)
            goto done;
        for (int j = 0; j < z; j++)
            for (int i = 0; i < r; i++)
                T[(size_t)j * r + i] = W[(size_t)(r + j) * n + i];
        cblas_dtrsm(CblasColMajor, CblasLeft, CblasUpper, CblasNoTrans, CblasNonUnit, r, z, 1.0,
                    sp->U, r, T, r);
        for (int j = 0; j < z; j++) {
            for (int i = 0; i < r; i++)
                sp->Z[(size_t)j * n + sp->yi[i]] = -T[(size_t)j * r + i];
            sp->Z[(size_t)j * n + sp->zi[j]] = 1.0;
        }
        free(T);
        /* KZ = K Z, Kzz = Z' K Z */
        cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, n, z, n, 1.0, K->a, n, sp->Z, n,
                    0.0, KZ, n);
        cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, z, z, n, 1.0, sp->Z, n, KZ, n, 0.0,
                    Kzz, z);
        for (int j = 0; j < z; j++)
            for (int i = 0; i < j; i++)
                Kzz[(size_t)j * z + i] = Kzz[(size_t)i * z + j] =
                    0.5 * (Kzz[(size_t)j * z + i] + Kzz[(size_t)i * z + j]);
        /* S = Kzz^-1 K_zy, K_zy = (Y' K Z)' = rows yi of KZ, transposed */
        for (int i = 0; i < r; i++)
            for (int j = 0; j < z; j++)
                sp->S[(size_t)i * z + j] = KZ[(size_t)j * n + sp->yi[i]];
        int chol;
        if ((rc = eig_definite(z, Kzz, Lzz, &chol, &sp->neg_zz)) < 0)
            goto done;
        if (chol) { /* S = Kzz^-1 S by the Cholesky factor */
            rc = dm_lapack_status(LAPACKE_dpotrs_work(LAPACK_COL_MAJOR, 'L', z, r, Lzz, z, sp->S, z),
                                  SM_LAPACK_FAILED);
        } else { /* indefinite: LU; an exactly singular Kzz is SM_SINGULAR */
            int *ip = malloc((size_t)z * sizeof(int));
            rc = ip ? dm_lapack_status(LAPACKE_dgesv_work(LAPACK_COL_MAJOR, z, r, Kzz, z, ip, sp->S, z),
                                       SM_SINGULAR)
                    : SM_NOMEM;
            free(ip);
        }
        if (rc < 0)
            goto done;
        /* Kr -= K_yz S */
        for (int j = 0; j < r; j++)
            for (int i = 0; i < r; i++) {
                double t = 0;
                for (int p = 0; p < z; p++)
                    t += KZ[(size_t)p * n + sp->yi[i]] * sp->S[(size_t)j * z + p];
                sp->Kr[(size_t)j * r + i] -= t;
            }
    }
    for (int j = 0; j < r; j++)
        for (int i = 0; i < j; i++)
            sp->Kr[(size_t)j * r + i] = sp->Kr[(size_t)i * r + j] =
                0.5 * (sp->Kr[(size_t)j * r + i] + sp->Kr[(size_t)i * r + j]);
    rc = SM_OK;
done:
    free(W);
    free(piv);
    free(KZ);
    free(Kzz);
    free(Lzz);
    return rc;
}

/* x = Y a + Z b, b = -S a, for the real vector a (r) into x (n). */
static void eig_expand(int n, const eig_split *sp, const double *a, double *x)
{
    memset(x, 0, (size_t)n * sizeof(double));
    for (int i = 0; i < sp->r; i++)
        x[sp->yi[i]] = a[i];
    for (int j = 0; j < sp->z; j++) {
        double b = 0;
        for (int i = 0; i < sp->r; i++)
            b -= sp->S[(size_t)i * sp->z + j] * a[i];
        for (int i = 0; i < n; i++)
            x[i] += sp->Z[(size_t)j * n + i] * b;
    }
}

int eig_alloc_out(sm_eig_out *o, int n, int k)
{
    o->n_modes = k;
    o->wre = dm_vec((size_t)k);
    o->wim = dm_vec((size_t)k);
    o->xre = dm_vec((size_t)n * k);
    o->xim = dm_vec((size_t)n * k);
    return o->wre && o->wim && o->xre && o->xim ? SM_OK : SM_NOMEM;
}

/*
 * K x = w^2 M x on the condensed problem with K_red = L L' positive definite:
 * the largest eigenvalues 1/w^2 of L^-1 M_yy L^-T = B B', B = L^-1 U'.  The
 * lowest frequencies are then accurate relative to themselves (the form
 * U^-T K U^-1 below resolves them only relative to the highest one: ~1e-9
 * at 48 elements).  Returns SM_OK, SM_NOMEM, or SM_LAPACK_FAILED when the
 * caller should use eig_undamped.
 */
static int eig_undamped_inverse(int n, const eig_split *sp, const double *L, int k, sm_eig_out *o)
{
    int r = sp->r, found = 0, rc = SM_NOMEM;
    double *B = dm_vec((size_t)r * r), *A = dm_vec((size_t)r * r), *w = dm_vec((size_t)r);
    double *V = dm_vec((size_t)r * k);
    int *sup = malloc(2 * (size_t)k * sizeof(int));
    if (!B || !A || !w || !V || !sup || eig_alloc_out(o, n, k))
        goto done;
    for (int j = 0; j < r; j++) /* B = U' */
        for (int i = 0; i <= j; i++)
            B[(size_t)i * r + j] = sp->U[(size_t)j * r + i];
    cblas_dtrsm(CblasColMajor, CblasLeft, CblasLower, CblasNoTrans, CblasNonUnit, r, r, 1.0, L, r, B, r);
    cblas_dsyrk(CblasColMajor, CblasLower, CblasNoTrans, r, r, 1.0, B, r, 0.0, A, r);
    rc = dm_lapack_status(LAPACKE_dsyevr(LAPACK_COL_MAJOR, 'V', 'I', 'L', r, A, r, 0, 0, r - k + 1, r, 0.0, &found,
                                         w, V, r, sup),
                          SM_LAPACK_FAILED);
    if (rc == SM_OK && (found != k || !(w[0] > 0)))
        rc = SM_LAPACK_FAILED;
    if (rc < 0)
        goto done;
    /* a = L^-T v */
    cblas_dtrsm(CblasColMajor, CblasLeft, CblasLower, CblasTrans, CblasNonUnit, r, k, 1.0, L, r, V, r);
    o->max_re = 0;
    for (int j = 0; j < k; j++) { /* ascending w: descending 1/w^2 */
        int c = k - 1 - j;
        o->wre[j] = 0;
        o->wim[j] = 1.0 / sqrt(w[c]);
        eig_expand(n, sp, V + (size_t)c * r, o->xre + (size_t)j * n);
    }
    rc = SM_OK;
done:
    if (rc < 0)
        eig_out_free(o);
    free(B);
    free(A);
    free(w);
    free(V);
    free(sup);
    return rc;
}

/* K x = w^2 M x on the condensed problem. */
static int eig_undamped(int n, const eig_split *sp, int k, sm_eig_out *o)
{
    int r = sp->r, found = 0, rc = SM_NOMEM;
    double *A = dm_vec((size_t)r * r), *w = dm_vec((size_t)r), *V = dm_vec((size_t)r * k);
    int *sup = malloc(2 * (size_t)k * sizeof(int));
    if (!A || !w || !V || !sup || eig_alloc_out(o, n, k))
        goto done;
    /* A = U^-T Kr U^-1 */
    memcpy(A, sp->Kr, (size_t)r * r * sizeof(double));
    cblas_dtrsm(CblasColMajor, CblasLeft, CblasUpper, CblasTrans, CblasNonUnit, r, r, 1.0, sp->U, r, A, r);
    cblas_dtrsm(CblasColMajor, CblasRight, CblasUpper, CblasNoTrans, CblasNonUnit, r, r, 1.0, sp->U, r, A, r);
    rc = dm_lapack_status(
        LAPACKE_dsyevr(LAPACK_COL_MAJOR, 'V', 'I', 'L', r, A, r, 0, 0, 1, k, 0.0, &found, w, V, r, sup),
        SM_LAPACK_FAILED);
    if (rc == SM_OK && found != k)
        rc = SM_LAPACK_FAILED;
    if (rc < 0)
        goto done;
    /* a = U^-1 v */
    cblas_dtrsm(CblasColMajor, CblasLeft, CblasUpper, CblasNoTrans, CblasNonUnit, r, k, 1.0, sp->U, r, V, r);
    o->max_re = -INFINITY;
    for (int j = 0; j < k; j++) {
        if (w[j] >= 0) {
            o->wre[j] = 0;
            o->wim[j] = sqrt(w[j]);
        } else {
            o->wre[j] = sqrt(-w[j]);
            o->wim[j] = 0;
        }
        o->max_re = fmax(o->max_re, o->wre[j]);
        eig_expand(n, sp, V + (size_t)j * r, o->xre + (size_t)j * n);
    }
    rc = SM_OK;
done:
    free(A);
    free(w);
    free(V);
    free(sup);
    return rc;
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
 * eigenvalues w^2, each twice.  dsyevr gives the 2k lowest; each real
 * eigenvector v yields y = v - i S v / w with S y = i w y; the candidates are
 * orthonormalised (a pair gives one direction) and a Rayleigh-Ritz step on
 * -i S restores full accuracy (the squared problem alone loses digits of the
 * low frequencies to the high ones) and separates close frequencies.  About a
 * quarter of the floating-point work of zheevr on -i S.  Returns SM_OK, or
 * SM_LAPACK_FAILED when the caller should fall back to zheevr.
 */
static int eig_dir_lowest(int r, const double *B, const double *G, int k, double *w, double complex *Y)
{
    int N2 = 2 * r, m2 = 2 * k < N2 ? 2 * k : N2, found = 0, acc = 0, rc = SM_NOMEM;
    double *A = dm_vec((size_t)N2 * N2), *ev = dm_vec((size_t)N2), *V = dm_vec((size_t)N2 * m2);
    double *SV = dm_vec((size_t)N2 * m2), *Yr = dm_vec((size_t)N2 * k), *Yi = dm_vec((size_t)N2 * k);
    double *SYr = dm_vec((size_t)N2 * k), *SYi = dm_vec((size_t)N2 * k), *th = dm_vec((size_t)k);
    double complex *T = calloc((size_t)k * k, sizeof(double complex));
    double complex *SY = calloc((size_t)N2 * k, sizeof(double complex));
    double complex *Q = calloc((size_t)N2 * k, sizeof(double complex));
    int *sup = malloc(2 * (size_t)m2 * sizeof(int));
    if (!A || !ev || !V || !SV || !Yr || !Yi || !SYr || !SYi || !th || !T || !SY || !Q || !sup)
        goto done;
    /* lower triangle of S'S */
    cblas_dsyrk(CblasColMajor, CblasLower, CblasNoTrans, r, r, 1.0, B, r, 0.0, A, N2);
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasTrans, r, r, r, -1.0, G, r, B, r, 0.0, A + r, N2);
    cblas_dsyrk(CblasColMajor, CblasLower, CblasTrans, r, r, 1.0, B, r, 0.0, A + (size_t)r * N2 + r, N2);
    cblas_dsyrk(CblasColMajor, CblasLower, CblasTrans, r, r, 1.0, G, r, 1.0, A + (size_t)r * N2 + r, N2);
    rc = dm_lapack_status(
        LAPACKE_dsyevr(LAPACK_COL_MAJOR, 'V', 'I', 'L', N2, A, N2, 0, 0, 1, m2, 0.0, &found, ev, V, N2, sup),
        SM_LAPACK_FAILED);
    if (rc < 0)
        goto done;
    rc = SM_LAPACK_FAILED; /* from here on: the caller falls back to zheevr */
    if (found != m2)
        goto done;
    eig_dir_apply(r, B, G, m2, V, SV);
    /* candidates y = v - i S v / w, orthonormalised (twice) against the accepted ones */
    for (int j = 0; j < m2 && acc < k; j++) {
        if (!(ev[j] > 1e-14 * ev[m2 - 1]))
            goto done;
        double wj = sqrt(ev[j]), *yr = Yr + (size_t)acc * N2, *yi = Yi + (size_t)acc * N2, nrm = 0;
        for (int i = 0; i < N2; i++) {
            yr[i] = V[(size_t)j * N2 + i];
            yi[i] = -SV[(size_t)j * N2 + i] / wj;
            nrm += yr[i] * yr[i] + yi[i] * yi[i];
        }
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
            continue; /* the other half of an accepted pair */
        for (int i = 0; i < N2; i++) {
            yr[i] /= nrm;
            yi[i] /= nrm;
        }
        acc++;
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
    free(sup);
    return rc;
}

/* The k lowest positive eigenpairs of -i S by zheevr (the fallback). */
static int eig_dir_zheevr(int r, const double *B, const double *G, int k, double *w, double complex *Y)
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
 * i E = (-i S)^-1, without complex arithmetic on the 2r-sized problem: dsyevr gives the 2k
 * largest eigenvalues 1/w^2 of E'E; each real eigenvector v yields y = v + i w E v with
 * i E y = y / w; the candidates are orthonormalised (a pair gives one direction) and a
 * Rayleigh-Ritz step on i E restores full accuracy (the squared problem alone loses digits of a
 * frequency to the lowest one) and separates close frequencies.  About a quarter of the
 * floating-point work of zheevr on i E.  Returns SM_OK, or SM_LAPACK_FAILED when the caller
 * should fall back to zheevr.
 */
static int eig_skew_lowest(int r, const double *D, const double *F, int k, double *w, double complex *Y)
{
    /* kk = k + EIG_GUARD directions: a frequency just above the k-th (a close pair at the end
     * of the request) is then separated by the Rayleigh-Ritz step, not left out of the basis */
    int kk = k + EIG_GUARD < r ? k + EIG_GUARD : r, N2 = 2 * r, m2 = 2 * kk, found = 0, acc = 0, rc = SM_NOMEM;
    double *A = dm_vec((size_t)N2 * N2), *ev = dm_vec((size_t)N2), *V = dm_vec((size_t)N2 * m2);
    double *EV = dm_vec((size_t)N2 * m2), *Yr = dm_vec((size_t)N2 * kk), *Yi = dm_vec((size_t)N2 * kk);
    double *EYr = dm_vec((size_t)N2 * kk), *EYi = dm_vec((size_t)N2 * kk), *th = dm_vec((size_t)kk);
    double complex *T = calloc((size_t)kk * kk, sizeof(double complex));
    double complex *EY = calloc((size_t)N2 * kk, sizeof(double complex));
    double complex *Q = calloc((size_t)N2 * kk, sizeof(double complex));
    int *sup = malloc(2 * (size_t)m2 * sizeof(int));
    if (!A || !ev || !V || !EV || !Yr || !Yi || !EYr || !EYi || !th || !T || !EY || !Q || !sup)
        goto done;
    eig_inv_square(r, D, F, A);
    rc = dm_lapack_status(LAPACKE_dsyevr(LAPACK_COL_MAJOR, 'V', 'I', 'L', N2, A, N2, 0, 0, N2 - m2 + 1, N2, 0.0,
                                         &found, ev, V, N2, sup),
                          SM_LAPACK_FAILED);
    if (rc < 0)
        goto done;
    rc = SM_LAPACK_FAILED; /* from here on: the caller falls back to zheevr */
    if (found != m2)
        goto done;
    eig_inv_apply(r, D, F, m2, V, EV);
    /* candidates y = v + i E v / mu (mu = 1/w), largest mu first, orthonormalised (twice)
     * against the accepted ones */
    for (int j = m2 - 1; j >= 0 && acc < kk; j--) {
        if (!(ev[j] > 1e-14 * ev[m2 - 1]))
            goto done;
        double mu = sqrt(ev[j]), *yr = Yr + (size_t)acc * N2, *yi = Yi + (size_t)acc * N2, nrm = 0;
        for (int i = 0; i < N2; i++) {
            yr[i] = V[(size_t)j * N2 + i];
            yi[i] = EV[(size_t)j * N2 + i] / mu;
            nrm += yr[i] * yr[i] + yi[i] * yi[i];
        }
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
            continue; /* the other half of an accepted pair */
        for (int i = 0; i < N2; i++) {
            yr[i] /= nrm;
            yi[i] /= nrm;
        }
        acc++;
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
    free(sup);
    return rc;
}

/* The k lowest frequencies and vectors of i E by zheevr (the fallback). */
static int eig_skew_zheevr(int r, const double *D, const double *F, int k, double *w, double complex *Y)
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

/* sqrt(max_i Kr_ii / M_ii): a lower estimate of the highest frequency of the condensed problem
 * (M_yy = U'U). */
static double eig_wmax_estimate(const eig_split *sp)
{
    int r = sp->r;
    double w2 = 0;
    for (int i = 0; i < r; i++) {
        double m = 0;
        for (int p = 0; p <= i; p++)
            m += sp->U[(size_t)i * r + p] * sp->U[(size_t)i * r + p];
        w2 = fmax(w2, sp->Kr[(size_t)i * r + i] / m);
    }
    return sqrt(w2);
}

/*
 * Frequencies from i E carry a relative rounding error ~eps w_j / w_1 (their vectors likewise),
 * those of the direct form -i S ~eps w_max / w_j: from the first j0 with w_j^2 > w_1 w_max on
 * (only a request that reaches near the top of the spectrum, or a nearly free coordinate with
 * w_1 ~ 0) the modes are taken from the direct form, solved for the k lowest as well.  j0 is
 * moved past a cluster (a pair of nearly equal frequencies comes from one form).  A failure of
 * the direct form keeps the inverse one's modes.  Returns SM_OK or SM_NOMEM.
 */
static int eig_gyro_direct(const eig_split *sp, const double *L, const double *Cy, int k, double *w,
                           double complex *Y)
{
    int r = sp->r, N2 = 2 * r, j0 = 0, rc = SM_OK;
    double wmax = eig_wmax_estimate(sp);
    while (j0 < k && !(w[j0] * w[j0] > w[0] * wmax))
        j0++;
    while (j0 > 0 && j0 < k && w[j0] - w[j0 - 1] < 1e-6 * w[j0])
        j0++;
    if (j0 >= k)
        return SM_OK;
    double *B = dm_vec((size_t)r * r), *G = dm_vec((size_t)r * r), *wd = dm_vec((size_t)k);
    double complex *Yd = calloc((size_t)N2 * k, sizeof(double complex));
    rc = SM_NOMEM;
    if (!B || !G || !wd || !Yd)
        goto done;
    /* B = L' U^-1 */
    for (int j = 0; j < r; j++)
        for (int i = 0; i <= j; i++)
            B[(size_t)j * r + i] = L[(size_t)i * r + j];
    cblas_dtrsm(CblasColMajor, CblasRight, CblasUpper, CblasNoTrans, CblasNonUnit, r, r, 1.0, sp->U, r, B, r);
    /* G = U^-T C U^-1 */
    memcpy(G, Cy, (size_t)r * r * sizeof(double));
    cblas_dtrsm(CblasColMajor, CblasLeft, CblasUpper, CblasTrans, CblasNonUnit, r, r, 1.0, sp->U, r, G, r);
    cblas_dtrsm(CblasColMajor, CblasRight, CblasUpper, CblasNoTrans, CblasNonUnit, r, r, 1.0, sp->U, r, G, r);
    rc = eig_dir_lowest(r, B, G, k, wd, Yd);
    if (rc == SM_LAPACK_FAILED)
        rc = eig_dir_zheevr(r, B, G, k, wd, Yd);
    if (rc == SM_OK) {
        memcpy(w + j0, wd + j0, (size_t)(k - j0) * sizeof(double));
        memcpy(Y + (size_t)j0 * N2, Yd + (size_t)j0 * N2, (size_t)(k - j0) * N2 * sizeof(double complex));
    }
    rc = rc == SM_NOMEM ? SM_NOMEM : SM_OK;
done:
    free(B);
    free(G);
    free(wd);
    free(Yd);
    return rc;
}

/* Gyroscopic problem with K_red = L L' positive definite: Hermitian form. */
static int eig_gyro_hermitian(int n, const eig_split *sp, const double *L, const double *Cy, int k,
                              sm_eig_out *o)
{
    int r = sp->r, N2 = 2 * r, rc = SM_NOMEM;
    double *D = dm_vec((size_t)r * r), *F = dm_vec((size_t)r * r), *w = dm_vec((size_t)k);
    double *ar = dm_vec((size_t)r), *ai = dm_vec((size_t)r);
    double complex *Y = calloc((size_t)N2 * k, sizeof(double complex));
    if (!D || !F || !w || !ar || !ai || !Y || eig_alloc_out(o, n, k))
        goto done;
    /* D = U L^-T */
    for (int j = 0; j < r; j++)
        for (int i = 0; i <= j; i++)
            D[(size_t)j * r + i] = sp->U[(size_t)j * r + i];
    cblas_dtrsm(CblasColMajor, CblasRight, CblasLower, CblasTrans, CblasNonUnit, r, r, 1.0, L, r, D, r);
    /* F = L^-1 C L^-T */
    memcpy(F, Cy, (size_t)r * r * sizeof(double));
    cblas_dtrsm(CblasColMajor, CblasLeft, CblasLower, CblasNoTrans, CblasNonUnit, r, r, 1.0, L, r, F, r);
    cblas_dtrsm(CblasColMajor, CblasRight, CblasLower, CblasTrans, CblasNonUnit, r, r, 1.0, L, r, F, r);
    rc = eig_skew_lowest(r, D, F, k, w, Y);
    if (rc == SM_LAPACK_FAILED)
        rc = eig_skew_zheevr(r, D, F, k, w, Y);
    if (rc < 0)
        goto done;
    if ((rc = eig_gyro_direct(sp, L, Cy, k, w, Y)) < 0)
        goto done;
    o->max_re = 0;
    for (int j = 0; j < k; j++) {
        o->wre[j] = 0;
        o->wim[j] = w[j];
        /* a = L^-T y1 (real and imaginary parts) */
        for (int i = 0; i < r; i++) {
            ar[i] = creal(Y[(size_t)j * N2 + i]);
            ai[i] = cimag(Y[(size_t)j * N2 + i]);
        }
        cblas_dtrsv(CblasColMajor, CblasLower, CblasTrans, CblasNonUnit, r, L, r, ar, 1);
        cblas_dtrsv(CblasColMajor, CblasLower, CblasTrans, CblasNonUnit, r, L, r, ai, 1);
        eig_expand(n, sp, ar, o->xre + (size_t)j * n);
        eig_expand(n, sp, ai, o->xim + (size_t)j * n);
    }
    rc = SM_OK;
done:
    free(D);
    free(F);
    free(w);
    free(ar);
    free(ai);
    free(Y);
    return rc;
}

int eig_root_cmp(const void *a, const void *b)
{
    double x = ((const eig_root *)a)->key, y = ((const eig_root *)b)->key;
    return x < y ? -1 : x > y;
}

/* General gyroscopic problem (K_red indefinite): companion form and dgeev. */
static int eig_gyro_general(int n, const eig_split *sp, const double *Cy, int k, sm_eig_out *o)
{
    int r = sp->r, N2 = 2 * r, rc = SM_NOMEM, nr = 0;
    double *A = dm_vec((size_t)N2 * N2), *wr = dm_vec((size_t)N2), *wi = dm_vec((size_t)N2);
    double *VR = dm_vec((size_t)N2 * N2), *T = dm_vec((size_t)r * N2);
    double *ar = dm_vec((size_t)r), *ai = dm_vec((size_t)r);
    eig_root *roots = calloc((size_t)N2, sizeof(eig_root));
    if (!A || !wr || !wi || !VR || !T || !ar || !ai || !roots)
        goto done;
    /* T = M^-1 [K C] */
    for (int j = 0; j < r; j++)
        for (int i = 0; i < r; i++) {
            T[(size_t)j * r + i] = sp->Kr[(size_t)j * r + i];
            T[(size_t)(r + j) * r + i] = Cy[(size_t)j * r + i];
        }
    rc = dm_lapack_status(LAPACKE_dpotrs_work(LAPACK_COL_MAJOR, 'U', r, N2, sp->U, r, T, r),
                          SM_LAPACK_FAILED);
    if (rc < 0)
        goto done;
    for (int i = 0; i < r; i++) {
        A[(size_t)(r + i) * N2 + i] = 1.0;
        for (int j = 0; j < N2; j++)
            A[(size_t)j * N2 + r + i] = -T[(size_t)j * r + i];
    }
    rc = dm_lapack_status(LAPACKE_dgeev(LAPACK_COL_MAJOR, 'N', 'V', N2, A, N2, wr, wi, NULL, 1, VR, N2),
                          SM_LAPACK_FAILED);
    if (rc < 0)
        goto done;
    o->max_re = -INFINITY;
    for (int j = 0; j < N2; j++) {
        o->max_re = fmax(o->max_re, wr[j]);
        double mag = hypot(wr[j], wi[j]);
        int take = wi[j] > 1e-12 * mag || (fabs(wi[j]) <= 1e-12 * mag && wr[j] >= 0);
        if (!take)
            continue;
        roots[nr].re = wr[j];
        roots[nr].im = fabs(wi[j]);
        roots[nr].key = wi[j] * wi[j] - wr[j] * wr[j];
        roots[nr].col = j;
        nr++;
    }
    qsort(roots, (size_t)nr, sizeof *roots, eig_root_cmp);
    k = k < nr ? k : nr;
    rc = eig_alloc_out(o, n, k);
    if (rc < 0)
        goto done;
    for (int t = 0; t < k; t++) {
        int j = roots[t].col;
        o->wre[t] = roots[t].re;
        o->wim[t] = roots[t].im;
        for (int i = 0; i < r; i++) {
            if (wi[j] > 0) {
                ar[i] = VR[(size_t)j * N2 + i];
                ai[i] = VR[(size_t)(j + 1) * N2 + i];
            } else {
                ar[i] = VR[(size_t)j * N2 + i];
                ai[i] = 0;
            }
        }
        eig_expand(n, sp, ar, o->xre + (size_t)t * n);
        eig_expand(n, sp, ai, o->xim + (size_t)t * n);
    }
    rc = SM_OK;
done:
    free(A);
    free(wr);
    free(wi);
    free(VR);
    free(T);
    free(ar);
    free(ai);
    free(roots);
    return rc;
}

/**
 * Solve the linearised problem; out receives min(modes, r) modes ordered by
 * Im^2 - Re^2 of lambda (ascending w^2; divergent roots first), the
 * modal-coordinate vectors and the inertia of K.  Returns SM_OK,
 * SM_NOMEM, SM_SINGULAR or SM_LAPACK_FAILED.
 */
int eig_solve(int n, const dmat *M, const dmat *C, const dmat *K, int coriolis, int modes,
              sm_eig_out *out)
{
    eig_split sp;
    memset(out, 0, sizeof *out);
    int rc = eig_condense(n, M, K, &sp);
    double *L = NULL, *Cy = NULL;
    if (rc < 0)
        goto done;
    int r = sp.r, k = modes < r ? modes : r, chol = 0;
    rc = SM_NOMEM;
    L = dm_vec((size_t)r * r);
    Cy = dm_vec((size_t)r * r);
    if (!L || !Cy)
        goto done;
    int neg = 0;
    if ((rc = eig_definite(r, sp.Kr, L, &chol, &neg)) < 0)
        goto done;
    out->negative = sp.neg_zz + neg;
    if (!coriolis) {
        rc = chol ? eig_undamped_inverse(n, &sp, L, k, out) : SM_LAPACK_FAILED;
        if (rc == SM_LAPACK_FAILED)
            rc = eig_undamped(n, &sp, k, out);
    } else {
        for (int j = 0; j < r; j++)
            for (int i = 0; i < r; i++)
                Cy[(size_t)j * r + i] = DM(C, sp.yi[i], sp.yi[j]);
        rc = chol ? eig_gyro_hermitian(n, &sp, L, Cy, k, out) : eig_gyro_general(n, &sp, Cy, k, out);
    }
done:
    if (rc < 0)
        eig_out_free(out); /* no partial results */
    free(L);
    free(Cy);
    eig_split_free(&sp);
    return rc;
}
