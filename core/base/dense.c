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
