/*
 * dense.c — storage helpers for the column-major dmat used by the core, and
 * the one mapping from LAPACK info values to sm_status.
 */
#include "dense.h"
#include "spinmodal.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

int dm_alloc(dmat *m, int rows, int cols)
{
    size_t n = (size_t)(rows > 0 ? rows : 0) * (size_t)(cols > 0 ? cols : 0);
    m->rows = rows;
    m->cols = cols;
    m->a = calloc(n ? n : 1, sizeof(double));
    return m->a ? SM_OK : SM_NOMEM;
}

void dm_free(dmat *m)
{
    free(m->a);
    m->a = NULL;
    m->rows = m->cols = 0;
}

void dm_zero(dmat *m)
{
    memset(m->a, 0, (size_t)m->rows * (size_t)m->cols * sizeof(double));
}

double *dm_vec(size_t n)
{
    return calloc(n ? n : 1, sizeof(double));
}

double dm_norm(const double *x, int n)
{
    /* scaled sum of squares, safe from overflow */
    double scale = 0.0, ssq = 1.0;
    for (int i = 0; i < n; i++) {
        double a = fabs(x[i]);
        if (a == 0.0)
            continue;
        if (scale < a) {
            ssq = 1.0 + ssq * (scale / a) * (scale / a);
            scale = a;
        } else {
            ssq += (a / scale) * (a / scale);
        }
    }
    return scale * sqrt(ssq);
}

int dm_finite(const dmat *m)
{
    size_t n = (size_t)m->rows * (size_t)m->cols;
    for (size_t i = 0; i < n; i++)
        if (!isfinite(m->a[i]))
            return 0;
    return 1;
}

int dm_lapack_status(int info, int on_positive)
{
    if (info == 0)
        return SM_OK;
    if (info == LAPACK_WORK_MEMORY_ERROR)
        return SM_NOMEM;
    return info < 0 ? SM_LAPACK_FAILED : on_positive;
}

int dm_sytrf_negative(int n, const double *A, const int *ipiv)
{
    int neg = 0;
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
    return neg;
}

/* The unreduced blocks of the tridiagonal (d, e): split where e_j^2 <= |d_j d_j+1| ulp^2 + safmin,
 * LAPACK dstebz's test, so that dstein sees the blocks dsyevr's bisection saw.  isplit[b] is the
 * last row (1-based) of block b; returns the number of blocks. */
static int dm_tri_split(int n, const double *d, const double *e, int *isplit)
{
    const double ulp = LAPACKE_dlamch('P'), safmin = LAPACKE_dlamch('S');
    int nb = 0;
    for (int j = 1; j < n; j++)
        if (fabs(d[j] * d[j - 1]) * ulp * ulp + safmin > e[j - 1] * e[j - 1])
            isplit[nb++] = j;
    isplit[nb++] = n;
    return nb;
}

typedef struct dm_eigval {
    double w;  /* an eigenvalue of the tridiagonal */
    int block; /* its unreduced block, 1-based (dstein's iblock) */
} dm_eigval;

static int dm_eigval_cmp(const void *a, const void *b)
{
    const dm_eigval *x = a, *y = b;
    return x->w < y->w ? -1 : x->w > y->w ? 1 : x->block - y->block;
}

static int dm_eigval_block_cmp(const void *a, const void *b)
{
    const dm_eigval *x = a, *y = b;
    return x->block != y->block ? x->block - y->block : dm_eigval_cmp(a, b);
}

/* Doubles (and ints) of workspace given to LAPACK's symmetric eigen-solvers beyond what they ask
 * for.  OpenBLAS 0.3.21's dsymv_L kernel for the Prescott core (the one it runs on a CPU it does
 * not know: this machine's Xeon, model 207) reads up to three entries past its y, which dlatrd
 * (inside dsytrd) places at the end of the workspace: with the exact workspace the high-level
 * LAPACKE routines allocate, the read left the block (valgrind with OPENBLAS_CORETYPE=Prescott:
 * dsytrd, dsyevx, dsyevr for all eigenvalues; a segmentation fault under AddressSanitizer where
 * the block ended a mapping).  dm_syev_range and dm_sy_lowest call the _work routines with the
 * workspace LAPACK asks for plus this, so the blocking and the bits are the high-level
 * routines'. */
#define DM_SYEV_PAD 64

/* 1 when the lower triangle of A (n x n, leading dimension n) holds a NaN: what LAPACKE's
 * high-level symmetric routines refuse (dsy_nancheck). */
static int dm_sy_nan(int n, const double *A)
{
    for (int j = 0; j < n; j++)
        for (int i = j; i < n; i++)
            if (isnan(A[(size_t)j * n + i]))
                return 1;
    return 0;
}

/* dm_syev_range's route without bisection (dense.h). */
static int dm_syev_tri(int n, double *A, int il, int iu, double *w, double *Z, int ldz)
{
    int m = iu - il + 1, info = LAPACK_WORK_MEMORY_ERROR;
    double *d = malloc(4 * (size_t)n * sizeof(double)), *e = d + n, *tau = e + n, *dd = tau + n;
    double *ee = malloc((size_t)n * sizeof(double)), *wsel = malloc((size_t)m * sizeof(double));
    dm_eigval *ev = malloc((size_t)n * sizeof(dm_eigval));
    int *isplit = malloc((size_t)n * sizeof(int)), *iblock = malloc((size_t)m * sizeof(int));
    int *iwork = malloc(((size_t)n + 2 * (size_t)m) * sizeof(int)), *ifail = iwork + n,
        *perm = ifail + m;
    double *work = NULL, *V = NULL, q1 = 0, q2 = 0;
    if (!d || !ee || !wsel || !ev || !isplit || !iblock || !iwork)
        goto done;
    /* workspace: the most of what dsytrd and dormtr ask for and dstein's 5 n, and DM_SYEV_PAD
     * beyond; each routine is told its own optimum (dormtr's blocks, and so its last bits, change
     * with the size it is told) */
    LAPACKE_dsytrd_work(LAPACK_COL_MAJOR, 'L', n, A, n, d, e, tau, &q1, -1);
    LAPACKE_dormtr_work(LAPACK_COL_MAJOR, 'L', 'L', 'N', n, m, A, n, tau, Z, ldz, &q2, -1);
    size_t lwork = (size_t)fmax(fmax(q1, q2), 5.0 * n);
    if (!(work = malloc((lwork + DM_SYEV_PAD) * sizeof(double))))
        goto done;
    /* A = Q T Q' (Householder; the reduction dsyevr makes) */
    if ((info = LAPACKE_dsytrd_work(LAPACK_COL_MAJOR, 'L', n, A, n, d, e, tau, work, (int)q1)) != 0)
        goto done;
    /* the eigenvalues of each unreduced block of T: root-free QL/QR (dsterf), O(n^2) */
    int nb = dm_tri_split(n, d, e, isplit), ne = 0;
    for (int b = 0, b0 = 0; b < nb; b0 = isplit[b++]) {
        int len = isplit[b] - b0;
        memcpy(dd, d + b0, (size_t)len * sizeof(double));
        if (len > 1)
            memcpy(ee, e + b0, (size_t)(len - 1) * sizeof(double));
        if ((info = LAPACKE_dsterf_work(len, dd, ee)) != 0)
            goto done;
        for (int j = 0; j < len; j++)
            ev[ne++] = (dm_eigval){dd[j], b + 1};
    }
    /* the il-th to iu-th smallest, grouped by block for dstein */
    qsort(ev, (size_t)n, sizeof *ev, dm_eigval_cmp);
    qsort(ev + il - 1, (size_t)m, sizeof *ev, dm_eigval_block_cmp);
    for (int j = 0; j < m; j++) {
        wsel[j] = ev[il - 1 + j].w;
        iblock[j] = ev[il - 1 + j].block;
    }
    /* ascending order, as dsyevr returns them: column j of Z is wsel[perm[j]]'s vector */
    int sorted = 1;
    for (int j = 0; j < m; j++)
        perm[j] = j;
    for (int j = 1; j < m; j++) /* insertion sort: the blocks are few, the order nearly right */
        for (int i = j; i > 0 && wsel[perm[i]] < wsel[perm[i - 1]]; i--) {
            int t = perm[i];
            perm[i] = perm[i - 1];
            perm[i - 1] = t;
            sorted = 0;
        }
    int ldv = sorted ? ldz : n;
    V = sorted ? Z : malloc((size_t)n * m * sizeof(double));
    if (!V) {
        info = LAPACK_WORK_MEMORY_ERROR;
        goto done;
    }
    /* the vectors of T by inverse iteration (dstein), then V = Q V */
    info = LAPACKE_dstein_work(LAPACK_COL_MAJOR, n, d, e, m, wsel, iblock, isplit, V, ldv, work,
                               iwork, ifail);
    if (info == 0)
        info = LAPACKE_dormtr_work(LAPACK_COL_MAJOR, 'L', 'L', 'N', n, m, A, n, tau, V, ldv, work,
                                   (int)q2);
    for (int j = 0; j < m; j++) {
        w[j] = wsel[perm[j]];
        if (!sorted && info == 0)
            memcpy(Z + (size_t)j * ldz, V + (size_t)perm[j] * n, (size_t)n * sizeof(double));
    }
done:
    if (V != Z)
        free(V);
    free(work);
    free(d);
    free(ee);
    free(wsel);
    free(ev);
    free(isplit);
    free(iblock);
    free(iwork);
    return info;
}

int dm_syev_range(int dsyevr_bits, int n, double *A, int il, int iu, double *w, double *Z, int ldz)
{
    if (dm_sy_nan(n, A))
        return -6; /* LAPACKE_dsyevr's answer */
    if (!dsyevr_bits)
        return dm_syev_tri(n, A, il, iu, w, Z, ldz);
    /* dsyevr with the workspace it asks for (so the same blocking and bits as LAPACKE_dsyevr) and
     * DM_SYEV_PAD beyond it; its w takes n values (its bisection may find more at a tie, then
     * discards them) */
    int m = iu - il + 1, found = 0, liwork = 0, info = LAPACK_WORK_MEMORY_ERROR;
    double q = 0;
    LAPACKE_dsyevr_work(LAPACK_COL_MAJOR, 'V', 'I', 'L', n, A, n, 0, 0, il, iu, 0.0, &found, w, Z,
                        ldz, NULL, &q, -1, &liwork, -1);
    int lwork = (int)q;
    int *sup = malloc(2 * (size_t)m * sizeof(int)),
        *iwork = malloc(((size_t)liwork + DM_SYEV_PAD) * sizeof(int));
    double *wf = malloc((size_t)n * sizeof(double)),
           *work = malloc(((size_t)lwork + DM_SYEV_PAD) * sizeof(double));
    if (sup && iwork && wf && work)
        info = LAPACKE_dsyevr_work(LAPACK_COL_MAJOR, 'V', 'I', 'L', n, A, n, 0, 0, il, iu, 0.0,
                                   &found, wf, Z, ldz, sup, work, lwork, iwork, liwork);
    if (info == 0 && found != m)
        info = 1;
    if (info == 0)
        memcpy(w, wf, (size_t)m * sizeof(double));
    free(sup);
    free(iwork);
    free(wf);
    free(work);
    return info;
}

int dm_sy_lowest(int n, double *A, double *lambda)
{
    if (dm_sy_nan(n, A))
        return -6; /* LAPACKE_dsyevx's answer */
    int found = 0, info = LAPACK_WORK_MEMORY_ERROR;
    double q = 0, *w = malloc((size_t)(n ? n : 1) * sizeof(double)), *work = NULL;
    int *iwork = malloc(5 * (size_t)(n ? n : 1) * sizeof(int)),
        *ifail = malloc((size_t)(n ? n : 1) * sizeof(int));
    if (!w || !iwork || !ifail)
        goto done;
    LAPACKE_dsyevx_work(LAPACK_COL_MAJOR, 'N', 'I', 'L', n, A, n, 0, 0, 1, 1, 0.0, &found, w, NULL,
                        1, &q, -1, iwork, ifail);
    int lwork = (int)q;
    if (!(work = malloc(((size_t)lwork + DM_SYEV_PAD) * sizeof(double))))
        goto done;
    info = LAPACKE_dsyevx_work(LAPACK_COL_MAJOR, 'N', 'I', 'L', n, A, n, 0, 0, 1, 1, 0.0, &found, w,
                               NULL, 1, work, lwork, iwork, ifail);
    if (info == 0 && found != 1)
        info = 1;
    if (info == 0)
        *lambda = w[0];
done:
    free(w);
    free(work);
    free(iwork);
    free(ifail);
    return info;
}

/* y (rows) = sum over p = 0..cols-1 in order of A(:, p) x[p] (A column-major, leading dimension
 * rows), each entry summed from 0: column updates, vectorised across the entries of y. */
static void dm_colsum_ordered(int rows, int cols, const double *restrict A,
                              const double *restrict x, double *restrict y)
{
    for (int i = 0; i < rows; i++)
        y[i] = 0;
    for (int p = 0; p < cols; p++) {
        const double *restrict ap = A + (size_t)p * rows;
        double xp = x[p];
        for (int i = 0; i < rows; i++)
            y[i] += ap[i] * xp;
    }
}

int dm_ptap_ordered(int n, int m, const double *K, const double *N, double *KN, double *C)
{
    double *Nt = dm_vec((size_t)m * (size_t)n); /* Nt[p m + i] = N(p, i): N' column-major */
    if (!Nt)
        return SM_NOMEM;
    for (int i = 0; i < m; i++)
        for (int p = 0; p < n; p++)
            Nt[(size_t)p * m + i] = N[(size_t)i * n + p];
    for (int j = 0; j < m; j++) /* KN(:, j) = sum_p K(:, p) N(p, j) */
        dm_colsum_ordered(n, n, K, N + (size_t)j * n, KN + (size_t)j * n);
    for (int j = 0; j < m; j++) /* C(:, j) = sum_p N(p, :)' KN(p, j) */
        dm_colsum_ordered(m, n, Nt, KN + (size_t)j * n, C + (size_t)j * m);
    free(Nt);
    return SM_OK;
}
