/*
 * test_blas_buffers.c — OpenBLAS work buffers kept per thread (server/blas_buffers.c), linked as
 * both programs link it (OpenBLAS's archive, -Wl,--wrap; tests/server/meson.build).
 *
 *   1. the wrap is in force: after a BLAS call the thread keeps one buffer, and a second call
 *      reuses it (nothing more taken from OpenBLAS);
 *   2. 8 threads doing the same dsymv, dgemm and LU 200 times each get the single thread's
 *      results bit for bit, and hold at most 2 buffers each meanwhile;
 *   3. 1 000 short-lived threads, each making BLAS calls, give their buffers back when they end:
 *      afterwards only the main thread's are out (OpenBLAS's own table has 128 + 512 entries, so
 *      1 000 threads that kept theirs would exhaust it).
 * Exit 0 when every check passes, 1 otherwise; prints each failure.
 */
#include "blas_buffers.h"

#include <cblas.h>
#include <lapacke.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

extern void openblas_set_num_threads(int n);
/* Fortran BLAS (its interface takes a work buffer: the calls dsyevr's reduction makes). */
extern void dsymv_(const char *uplo, const int *n, const double *alpha, const double *a,
                   const int *lda, const double *x, const int *incx, const double *beta, double *y,
                   const int *incy);

#define N 120      /* matrix order: large enough for OpenBLAS's packed paths */
#define THREADS 8  /* concurrent threads of check 2 */
#define ROUNDS 200 /* calls of each kind per thread in check 2 */
#define SHORT 1000 /* short-lived threads of check 3 */

static int failures;

static void check(int ok, const char *what)
{
    if (!ok) {
        printf("FAIL: %s\n", what);
        failures++;
    }
}

static double A[N * N], B[N * N];

/* One round: y = A x, C = A B, LU of A + n I; the results into out (N + N*N + N*N). */
static int round_of_calls(double *out)
{
    double x[N], *y = out, *c = out + N, *lu = out + N + N * N;
    int n = N, one = 1, piv[N];
    double alpha = 1.0, beta = 0.0;
    for (int i = 0; i < N; i++)
        x[i] = 1.0 / (1.0 + i);
    dsymv_("L", &n, &alpha, A, &n, x, &one, &beta, y, &one);
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, N, N, N, 1.0, A, N, B, N, 0.0, c, N);
    memcpy(lu, A, sizeof A);
    for (int i = 0; i < N; i++)
        lu[i + i * N] += N;
    return LAPACKE_dgetrf(LAPACK_COL_MAJOR, N, N, lu, N, piv);
}

#define OUT_LEN (N + 2 * N * N)
static double reference[OUT_LEN];

typedef struct worker {
    int same;     /* every round equal to the reference, bit for bit */
    int max_held; /* the most buffers the thread held after a round */
} worker;

static void *run_rounds(void *arg)
{
    worker *w = arg;
    double *out = malloc(sizeof(double) * OUT_LEN);
    w->same = out != NULL;
    for (int r = 0; out && r < ROUNDS; r++) {
        if (round_of_calls(out) != 0 || memcmp(out, reference, sizeof(double) * OUT_LEN) != 0)
            w->same = 0;
        if (blas_buffers_held() > w->max_held)
            w->max_held = blas_buffers_held();
    }
    free(out);
    return NULL;
}

static void *one_call(void *arg)
{
    (void)arg;
    double y[N], x[N];
    int n = N, one = 1;
    double alpha = 1.0, beta = 0.0;
    for (int i = 0; i < N; i++)
        x[i] = 1.0;
    dsymv_("L", &n, &alpha, A, &n, x, &one, &beta, y, &one);
    return NULL;
}

int main(void)
{
    setvbuf(stdout, NULL, _IONBF, 0); /* a failure prints before any crash */
    openblas_set_num_threads(1);
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            A[i + j * N] = 1.0 / (1.0 + i + j);
            B[i + j * N] = (double)((i * 7 + j * 3) % 11) - 5.0;
        }

    /* 1: the wrap is in force */
    check(round_of_calls(reference) == 0, "dgetrf of A + nI");
    int out0 = blas_buffers_out();
    check(blas_buffers_held() == 1, "the main thread keeps one buffer after its calls");
    check(out0 >= 1, "buffers taken from OpenBLAS are counted (blas_memory_alloc is wrapped)");
    double *again = malloc(sizeof(double) * OUT_LEN);
    check(again && round_of_calls(again) == 0 &&
              memcmp(again, reference, sizeof(double) * OUT_LEN) == 0,
          "a second round gives the same bits");
    check(blas_buffers_out() == out0, "a second round takes no new buffer from OpenBLAS");
    free(again);

    /* 2: threads at once, same bits */
    pthread_t th[THREADS];
    worker w[THREADS];
    memset(w, 0, sizeof w);
    for (int t = 0; t < THREADS; t++)
        check(pthread_create(&th[t], NULL, run_rounds, &w[t]) == 0, "pthread_create");
    for (int t = 0; t < THREADS; t++) {
        pthread_join(th[t], NULL);
        check(w[t].same, "a thread's rounds equal the single thread's, bit for bit");
        check(w[t].max_held >= 1 && w[t].max_held <= 2, "a thread keeps 1 or 2 buffers");
    }
    check(blas_buffers_out() == out0, "the 8 threads gave their buffers back when they ended");

    /* 3: many short-lived threads */
    for (int k = 0; k < SHORT; k++) {
        pthread_t t1;
        if (pthread_create(&t1, NULL, one_call, NULL) != 0) {
            check(0, "pthread_create (short-lived)");
            break;
        }
        pthread_join(t1, NULL);
    }
    char msg[160];
    snprintf(msg, sizeof msg,
             "after %d short-lived threads %d buffers are out (the main thread's %d)", SHORT,
             blas_buffers_out(), out0);
    check(blas_buffers_out() == out0, msg);

    printf("%s: %d failure(s)\n", failures ? "FAIL" : "ok", failures);
    return failures ? 1 : 0;
}
