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
#include "eigen_skew.h"

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
    int *ipiv = malloc((size_t)n * sizeof(int));
    if (!ipiv)
        return SM_NOMEM;
    int rc = dm_lapack_status(LAPACKE_dsytrf(LAPACK_COL_MAJOR, 'L', n, A, n, ipiv), SM_OK);
    if (rc == SM_OK)
        *neg_out = dm_sytrf_negative(n, A, ipiv);
    free(ipiv);
    return rc;
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
static int eig_undamped_inverse(int fixed_bits, int n, const eig_split *sp, const double *L, int k,
                                sm_eig_out *o)
{
    int r = sp->r, rc = SM_NOMEM;
    double *B = dm_vec((size_t)r * r), *A = dm_vec((size_t)r * r), *w = dm_vec((size_t)r);
    double *V = dm_vec((size_t)r * k);
    if (!B || !A || !w || !V || eig_alloc_out(o, n, k))
        goto done;
    for (int j = 0; j < r; j++) /* B = U' */
        for (int i = 0; i <= j; i++)
            B[(size_t)i * r + j] = sp->U[(size_t)j * r + i];
    cblas_dtrsm(CblasColMajor, CblasLeft, CblasLower, CblasNoTrans, CblasNonUnit, r, r, 1.0, L, r, B, r);
    cblas_dsyrk(CblasColMajor, CblasLower, CblasNoTrans, r, r, 1.0, B, r, 0.0, A, r);
    rc = dm_lapack_status(dm_syev_range(fixed_bits, r, A, r - k + 1, r, w, V, r), SM_LAPACK_FAILED);
    if (rc == SM_OK && !(w[0] > 0))
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
    return rc;
}

/* K x = w^2 M x on the condensed problem. */
static int eig_undamped(int fixed_bits, int n, const eig_split *sp, int k, sm_eig_out *o)
{
    int r = sp->r, rc = SM_NOMEM;
    double *A = dm_vec((size_t)r * r), *w = dm_vec((size_t)r), *V = dm_vec((size_t)r * k);
    if (!A || !w || !V || eig_alloc_out(o, n, k))
        goto done;
    /* A = U^-T Kr U^-1 */
    memcpy(A, sp->Kr, (size_t)r * r * sizeof(double));
    cblas_dtrsm(CblasColMajor, CblasLeft, CblasUpper, CblasTrans, CblasNonUnit, r, r, 1.0, sp->U, r, A, r);
    cblas_dtrsm(CblasColMajor, CblasRight, CblasUpper, CblasNoTrans, CblasNonUnit, r, r, 1.0, sp->U, r, A, r);
    rc = dm_lapack_status(dm_syev_range(fixed_bits, r, A, 1, k, w, V, r), SM_LAPACK_FAILED);
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
static int eig_gyro_direct(int fixed_bits, const eig_split *sp, const double *L, const double *Cy,
                           int k, double *w, double complex *Y)
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
    rc = eig_dir_lowest(fixed_bits, r, B, G, k, wd, Yd);
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
static int eig_gyro_hermitian(int fixed_bits, int n, const eig_split *sp, const double *L,
                              const double *Cy, int k, sm_eig_out *o)
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
    rc = eig_skew_lowest(fixed_bits, r, D, F, k, w, Y);
    if (rc == SM_LAPACK_FAILED)
        rc = eig_skew_zheevr(r, D, F, k, w, Y);
    if (rc < 0)
        goto done;
    if ((rc = eig_gyro_direct(fixed_bits, sp, L, Cy, k, w, Y)) < 0)
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
              int fixed_bits, sm_eig_out *out)
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
        rc = chol ? eig_undamped_inverse(fixed_bits, n, &sp, L, k, out) : SM_LAPACK_FAILED;
        if (rc == SM_LAPACK_FAILED)
            rc = eig_undamped(fixed_bits, n, &sp, k, out);
    } else {
        for (int j = 0; j < r; j++)
            for (int i = 0; i < r; i++)
                Cy[(size_t)j * r + i] = DM(C, sp.yi[i], sp.yi[j]);
        rc = chol ? eig_gyro_hermitian(fixed_bits, n, &sp, L, Cy, k, out)
                  : eig_gyro_general(n, &sp, Cy, k, out);
    }
done:
    if (rc < 0)
        eig_out_free(out); /* no partial results */
    free(L);
    free(Cy);
    eig_split_free(&sp);
    return rc;
}

/* Measured on one core of the development machine (issue 23), a speed on the dense path: 12 ms at
 * 191 coordinates with 3 modes (the 32 + 32 element angled beam, Newton included); with n/8 modes
 * (a spatial blade) 0.05 s at 180, 0.18 s at 300, 1.04 s at 600, 9.6 s at 1200 with Coriolis, 1.5 s
 * at 1200 without.  The estimate takes the low end (few modes): a request is refused only when it
 * surely runs past the limit; the job time limit bounds the rest. */
double sm_dense_seconds(int n, int coriolis)
{
    double x = (double)(n > 0 ? n : 0);
    return (coriolis ? 1.8e-9 : 0.3e-9) * x * x * x;
}
