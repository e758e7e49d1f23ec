/*
 * csym.c — symmetric sparse matrices of one substructure and their LDL'
 * factorisation (lowmodes.h), so that the few lowest component modes of a
 * large frame cost O(D) per solve instead of a dense O(D^3) decomposition.
 *
 * A frame is a tree of 2-node beam elements (a chain for a single member,
 * branches at joints), clamped at its root.  Its Kbar and Mbar have one dense
 * bs x bs block per node and per element: csym_pattern builds that pattern
 * (both triangles, compressed columns), modes.c and modes3.c add the element
 * entries into it (csym_add through a csym_sink).
 *
 * csym_factor orders the DOFs by reverse Cuthill-McKee (breadth-first levels
 * from a minimum-degree DOF, reversed): on a tree every node is then
 * eliminated after all nodes farther from the start, so its only remaining
 * neighbour is the node it was reached from and the factor has no fill
 * outside the blocks (a chain is banded).  The factorisation itself is the
 * up-looking sparse LDL' (T. A. Davis, Direct Methods for Sparse Linear
 * Systems, SIAM 2006, ch. 4): elimination tree and row patterns first, then
 * row k of L from the triangular solve L D l_k = A(0:k-1, k).  No pivoting: A
 * is positive definite (Kbar of a clamped frame), a pivot <= 0 says it is not.
 */
#include "csym.h"
#include "spinmodal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void csym_free(csym *A)
{
    free(A->p);
    free(A->i);
    free(A->x);
    memset(A, 0, sizeof *A);
}

void csym_ldl_free(csym_ldl *F)
{
    free(F->perm);
    free(F->lp);
    free(F->li);
    free(F->lx);
    free(F->d);
    memset(F, 0, sizeof *F);
}

static int csym_cmp_int(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

/* Allocate A of order n with nz entries (p zeroed, x zeroed).  SM_OK or SM_NOMEM. */
static int csym_alloc(csym *A, int n, size_t nz)
{
    memset(A, 0, sizeof *A);
    A->n = n;
    A->p = calloc((size_t)n + 1, sizeof(int));
    A->i = malloc((nz ? nz : 1) * sizeof(int));
    A->x = calloc(nz ? nz : 1, sizeof(double));
    return A->p && A->i && A->x ? SM_OK : SM_NOMEM;
}

/* Node adjacency (self included, ascending, no repeats): nodes of a in adj[ap[a] .. ap[a+1]). */
static int csym_adjacency(int nn, int ne, const int *ends, int **apo, int **adjo)
{
    int *ap = calloc((size_t)nn + 1, sizeof(int)), *adj = NULL, *fill = NULL, rc = SM_NOMEM;
    if (!ap)
        goto done;
    for (int a = 0; a < nn; a++)
        ap[a + 1] = 1; /* itself */
    for (int e = 0; e < ne; e++)
        if (ends[2 * e] >= 0 && ends[2 * e + 1] >= 0) {
            ap[ends[2 * e] + 1]++;
            ap[ends[2 * e + 1] + 1]++;
        }
    for (int a = 0; a < nn; a++)
        ap[a + 1] += ap[a];
    adj = malloc((size_t)(ap[nn] ? ap[nn] : 1) * sizeof(int));
    fill = malloc((size_t)(nn ? nn : 1) * sizeof(int));
    if (!adj || !fill)
        goto done;
    for (int a = 0; a < nn; a++) {
        adj[ap[a]] = a;
        fill[a] = ap[a] + 1;
    }
    for (int e = 0; e < ne; e++) {
        int a = ends[2 * e], b = ends[2 * e + 1];
        if (a >= 0 && b >= 0) {
            adj[fill[a]++] = b;
            adj[fill[b]++] = a;
        }
    }
    /* sort each list and squeeze out repeats (two elements between the same nodes) */
    int w = 0;
    for (int a = 0; a < nn; a++) {
        int lo = ap[a], hi = ap[a + 1];
        qsort(adj + lo, (size_t)(hi - lo), sizeof(int), csym_cmp_int);
        ap[a] = w;
        for (int q = lo; q < hi; q++)
            if (q == lo || adj[q] != adj[q - 1])
                adj[w++] = adj[q];
    }
    ap[nn] = w;
    rc = SM_OK;
done:
    free(fill);
    *apo = ap;
    *adjo = adj;
    return rc;
}

int csym_pattern(csym *A, int nn, int bs, int ne, const int *ends)
{
    int *ap = NULL, *adj = NULL;
    memset(A, 0, sizeof *A);
    int rc = csym_adjacency(nn, ne, ends, &ap, &adj);
    if (rc == SM_OK)
        rc = csym_alloc(A, nn * bs, (size_t)ap[nn] * (size_t)(bs * bs));
    if (rc == SM_OK) {
        int q = 0;
        for (int a = 0; a < nn; a++)
            for (int c = 0; c < bs; c++) { /* column bs a + c: every DOF of every neighbour */
                A->p[bs * a + c] = q;
                for (int t = ap[a]; t < ap[a + 1]; t++)
                    for (int r = 0; r < bs; r++)
                        A->i[q++] = bs * adj[t] + r;
            }
        A->p[nn * bs] = q;
    }
    free(ap);
    free(adj);
    return rc;
}

/* Position of row r in column c of A, or -1. */
static int csym_find(const csym *A, int r, int c)
{
    int lo = A->p[c], hi = A->p[c + 1] - 1;
    while (lo <= hi) {
        int mid = lo + (hi - lo) / 2;
        if (A->i[mid] == r)
            return mid;
        if (A->i[mid] < r)
            lo = mid + 1;
        else
            hi = mid - 1;
    }
    return -1;
}

void csym_add(csym *A, int r, int c, double v)
{
    int q = csym_find(A, r, c);
    if (q >= 0)
        A->x[q] += v;
}

double csym_get(const csym *A, int r, int c)
{
    int q = csym_find(A, r, c);
    return q >= 0 ? A->x[q] : 0.0;
}

int csym_sub(const csym *A, int nk, const int *keep, csym *B)
{
    int *map = malloc((size_t)(A->n ? A->n : 1) * sizeof(int)), rc = SM_NOMEM;
    memset(B, 0, sizeof *B);
    if (!map)
        return SM_NOMEM;
    for (int r = 0; r < A->n; r++)
        map[r] = -1;
    for (int k = 0; k < nk; k++)
        map[keep[k]] = k;
    size_t nz = 0;
    for (int k = 0; k < nk; k++)
        for (int q = A->p[keep[k]]; q < A->p[keep[k] + 1]; q++)
            nz += map[A->i[q]] >= 0;
    if (csym_alloc(B, nk, nz) == SM_OK) {
        int w = 0;
        for (int k = 0; k < nk; k++) { /* keep ascending: rows stay ascending */
            B->p[k] = w;
            for (int q = A->p[keep[k]]; q < A->p[keep[k] + 1]; q++)
                if (map[A->i[q]] >= 0) {
                    B->i[w] = map[A->i[q]];
                    B->x[w++] = A->x[q];
                }
        }
        B->p[nk] = w;
        rc = SM_OK;
    }
    free(map);
    return rc;
}

void csym_mul(const csym *A, int k, const double *X, int ldx, double *Y, int ldy)
{
    for (int j = 0; j < k; j++) {
        const double *x = X + (size_t)ldx * j;
        double *y = Y + (size_t)ldy * j;
        for (int c = 0; c < A->n; c++) { /* y = sum_c A(:, c) x_c */
            double s = 0;
            for (int q = A->p[c]; q < A->p[c + 1]; q++)
                s += A->x[q] * x[A->i[q]]; /* A symmetric: row c of A . x */
            y[c] = s;
        }
    }
}

/*
 * Y = A X with every entry summed as an accurate dot product (Dot2 of Ogita, Rump & Oishi,
 * SIAM J. Sci. Comput. 26, 2005: error-free products by fma, error-free sums, the errors
 * accumulated): as if in twice the working precision, then rounded.  For a stiffness matrix and
 * a smooth vector the row sums of K x cancel by up to the condition number of K (1e9 and more
 * for a long chain of short beams), so the plain sum keeps only a few digits of K x and
 * x' K x of a low mode comes out wrong in its tenth digit.
 */
void csym_mul_acc(const csym *A, int k, const double *X, int ldx, double *Y, int ldy)
{
    for (int j = 0; j < k; j++) {
        const double *x = X + (size_t)ldx * j;
        double *y = Y + (size_t)ldy * j;
        for (int c = 0; c < A->n; c++) {
            double s = 0, e = 0; /* sum = s + e */
            for (int q = A->p[c]; q < A->p[c + 1]; q++) {
                double a = A->x[q], b = x[A->i[q]];
                double h = a * b, r = fma(a, b, -h); /* a b = h + r exactly */
                double t = s + h, z = t - s;          /* s + h = t + (error) exactly */
                e += (s - (t - z)) + (h - z) + r;
                s = t;
            }
            y[c] = s + e;
        }
    }
}

/*
 * perm = reverse Cuthill-McKee order of the graph of A: each connected part
 * breadth first from a DOF of least degree, the DOFs of a level in ascending
 * degree, the whole order reversed.  mark: n ints of scratch.
 */
static void csym_rcm(const csym *A, int *perm, int *mark)
{
    int n = A->n, tail = 0;
    for (int r = 0; r < n; r++)
        mark[r] = 0;
    while (tail < n) {
        int start = -1;
        for (int r = 0; r < n; r++)
            if (!mark[r] && (start < 0 || A->p[r + 1] - A->p[r] < A->p[start + 1] - A->p[start]))
                start = r;
        int head = tail;
        perm[tail++] = start;
        mark[start] = 1;
        while (head < tail) {
            int v = perm[head++], first = tail;
            for (int q = A->p[v]; q < A->p[v + 1]; q++)
                if (!mark[A->i[q]]) {
                    mark[A->i[q]] = 1;
                    perm[tail++] = A->i[q];
                }
            for (int s = first + 1; s < tail; s++) { /* insertion sort by degree (stable) */
                int u = perm[s], du = A->p[u + 1] - A->p[u], t = s;
                for (; t > first && A->p[perm[t - 1] + 1] - A->p[perm[t - 1]] > du; t--)
                    perm[t] = perm[t - 1];
                perm[t] = u;
            }
        }
    }
    for (int a = 0, b = n - 1; a < b; a++, b--) {
        int t = perm[a];
        perm[a] = perm[b];
        perm[b] = t;
    }
}

/*
 * Elimination tree (parent) and column counts of L for P A P' (pinv: inverse
 * of F->perm), then F->lp.  flag, cnt: n ints of scratch.  SM_OK or SM_NOMEM.
 */
static int csym_symbolic(const csym *A, csym_ldl *F, const int *pinv, int *parent, int *flag, int *cnt)
{
    int n = A->n;
    for (int k = 0; k < n; k++) {
        parent[k] = -1;
        flag[k] = k;
        cnt[k] = 0;
        int c = F->perm[k];
        for (int q = A->p[c]; q < A->p[c + 1]; q++) /* A(i, k), i < k: the reach of i in the tree */
            for (int i = pinv[A->i[q]]; i < k && flag[i] != k; i = parent[i]) {
                if (parent[i] < 0)
                    parent[i] = k;
                cnt[i]++; /* L(k, i) != 0 */
                flag[i] = k;
            }
    }
    F->lp[0] = 0;
    for (int k = 0; k < n; k++)
        F->lp[k + 1] = F->lp[k] + cnt[k];
    size_t nz = (size_t)F->lp[n];
    F->li = malloc((nz ? nz : 1) * sizeof(int));
    F->lx = malloc((nz ? nz : 1) * sizeof(double));
    return F->li && F->lx ? SM_OK : SM_NOMEM;
}

/*
 * Row k of L and d_k for k = 0 .. n-1 (up-looking): y = A(0:k, k) scattered,
 * the nonzero pattern of row k = the tree reach of its entries, then
 * L(0:k-1, 0:k-1) D l = y by columns of L in topological order, d_k = a_kk - l' D l.
 * y: n doubles, pattern, flag, cnt: n ints (scratch).  SM_OK or SM_SINGULAR.
 */
static int csym_numeric(const csym *A, csym_ldl *F, const int *pinv, const int *parent, double *y,
                        int *pattern, int *flag, int *cnt)
{
    int n = A->n;
    for (int k = 0; k < n; k++) {
        y[k] = 0;
        flag[k] = k;
        cnt[k] = 0;
        int top = n, c = F->perm[k];
        for (int q = A->p[c]; q < A->p[c + 1]; q++) {
            int i = pinv[A->i[q]], len = 0;
            if (i > k)
                continue;
            y[i] += A->x[q];
            for (; flag[i] != k; i = parent[i]) { /* the path up to an already marked node */
                pattern[len++] = i;
                flag[i] = k;
            }
            while (len > 0)
                pattern[--top] = pattern[--len];
        }
        double dk = y[k];
        y[k] = 0;
        for (; top < n; top++) {
            int i = pattern[top], q2 = F->lp[i] + cnt[i];
            double yi = y[i];
            y[i] = 0;
            for (int q = F->lp[i]; q < q2; q++) /* y -= L(:, i) yi */
                y[F->li[q]] -= F->lx[q] * yi;
            double lki = yi / F->d[i]; /* l_ki = y_i / d_i */
            dk -= lki * yi;            /* d_k = a_kk - sum l_ki^2 d_i */
            F->li[q2] = k;
            F->lx[q2] = lki;
            cnt[i]++;
        }
        if (!(dk > 0))
            return SM_SINGULAR;
        F->d[k] = dk;
    }
    return SM_OK;
}

int csym_factor(const csym *A, csym_ldl *F)
{
    int n = A->n, rc = SM_NOMEM;
    size_t nn = (size_t)(n ? n : 1);
    memset(F, 0, sizeof *F);
    F->n = n;
    F->perm = malloc(nn * sizeof(int));
    F->lp = malloc((nn + 1) * sizeof(int));
    F->d = malloc(nn * sizeof(double));
    int *iw = malloc(5 * nn * sizeof(int)); /* pinv, parent, flag, cnt, pattern */
    double *y = malloc(nn * sizeof(double));
    if (!F->perm || !F->lp || !F->d || !iw || !y)
        goto done;
    int *pinv = iw, *parent = iw + nn, *flag = iw + 2 * nn, *cnt = iw + 3 * nn, *pattern = iw + 4 * nn;
    csym_rcm(A, F->perm, flag);
    for (int k = 0; k < n; k++)
        pinv[F->perm[k]] = k;
    if ((rc = csym_symbolic(A, F, pinv, parent, flag, cnt)) == SM_OK)
        rc = csym_numeric(A, F, pinv, parent, y, pattern, flag, cnt);
done:
    free(iw);
    free(y);
    return rc;
}

void csym_solve(const csym_ldl *F, int k, double *B, int ldb, double *work)
{
    int n = F->n;
    for (int j = 0; j < k; j++) {
        double *b = B + (size_t)ldb * j, *w = work;
        for (int t = 0; t < n; t++) /* w = P b */
            w[t] = b[F->perm[t]];
        for (int c = 0; c < n; c++) /* w = L \ w */
            for (int q = F->lp[c]; q < F->lp[c + 1]; q++)
                w[F->li[q]] -= F->lx[q] * w[c];
        for (int c = 0; c < n; c++) /* w = D \ w */
            w[c] /= F->d[c];
        for (int c = n - 1; c >= 0; c--) /* w = L' \ w */
            for (int q = F->lp[c]; q < F->lp[c + 1]; q++)
                w[c] -= F->lx[q] * w[F->li[q]];
        for (int t = 0; t < n; t++) /* b = P' w */
            b[F->perm[t]] = w[t];
    }
}

int csym_solve_refined(const csym *A, const csym_ldl *F, int k, double *B, int ldb)
{
    int n = A->n, rc = SM_NOMEM;
    size_t nk = (size_t)(n ? n : 1) * (size_t)(k ? k : 1);
    double *B0 = malloc(nk * sizeof(double)), *R = malloc(nk * sizeof(double));
    double *work = malloc((size_t)(n ? n : 1) * sizeof(double));
    if (!B0 || !R || !work)
        goto done;
    for (int j = 0; j < k; j++) /* B0 = B */
        memcpy(B0 + (size_t)n * j, B + (size_t)ldb * j, (size_t)n * sizeof(double));
    csym_solve(F, k, B, ldb, work);   /* X = A^-1 B0 */
    csym_mul_acc(A, k, B, ldb, R, n); /* R = B0 - A X */
    for (size_t t = 0; t < (size_t)n * k; t++)
        R[t] = B0[t] - R[t];
    csym_solve(F, k, R, n, work); /* X += A^-1 R */
    for (int j = 0; j < k; j++)
        for (int r = 0; r < n; r++)
            B[(size_t)ldb * j + r] += R[(size_t)n * j + r];
    rc = SM_OK;
done:
    free(B0);
    free(R);
    free(work);
    return rc;
}
