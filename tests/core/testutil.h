/*
 * testutil.h — tiny helpers shared by the core tests: a check macro that
 * counts failures, the paper's angled beam and a straight cantilever, and a
 * CSV reader for the reference files.
 */
#ifndef SM_TESTUTIL_H
#define SM_TESTUTIL_H

#include "spinmodal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int tu_failures = 0;
static int tu_checks = 0;

#define TU_CHECK(cond, ...)                                       \
    do {                                                          \
        tu_checks++;                                              \
        if (!(cond)) {                                            \
            tu_failures++;                                        \
            printf("FAIL %s:%d: ", __FILE__, __LINE__);           \
            printf(__VA_ARGS__);                                  \
            printf("\n");                                         \
        }                                                         \
    } while (0)

/* |got - want| <= tol, printed either way for the record */
#define TU_NEAR(got, want, tol, ...)                                          \
    do {                                                                      \
        double g_ = (got), w_ = (want), t_ = (tol);                           \
        tu_checks++;                                                          \
        int ok_ = fabs(g_ - w_) <= t_;                                        \
        if (!ok_)                                                             \
            tu_failures++;                                                    \
        printf("%s ", ok_ ? "ok  " : "FAIL");                                 \
        printf(__VA_ARGS__);                                                  \
        printf(": got %.6f want %.6f (err %.2e, tol %.1e)\n", g_, w_, g_ - w_, t_); \
    } while (0)

static inline int tu_finish(const char *name)
{
    printf("%s: %d checks, %d failures\n", name, tu_checks, tu_failures);
    return tu_failures ? 1 : 0;
}

/* st: one spatial member (mem, of section sec) between joints 0 and 1 at xy (x0, y0, x1, y1)
 * and z (z0, z1); the other fields of st are left as they are. */
static inline void tu_one_member3(sm_structure *st, double *xy, double *z, sm_section *sec,
                                  sm_member *mem)
{
    st->n_joints = 2;
    st->joint_xy = xy;
    st->joint_z = z;
    st->n_sections = 1;
    st->sections = sec;
    st->n_members = 1;
    st->members = mem;
    st->spatial = 1;
}

/* Paper Table 1 section and the angled beam of Fig. 5: O(0,0)-C(5,0)-P. */
typedef struct tu_angled {
    double xy[6];
    sm_section sec;
    sm_member mem[2];
    sm_structure st;
} tu_angled;

static inline void tu_angled_beam(tu_angled *a, double beta_deg, int e1, int e2)
{
    double b = beta_deg * 3.14159265358979323846 / 180.0;
    double xy[6] = {0, 0, 5, 0, 5 + 5 * cos(b), 5 * sin(b)};
    memcpy(a->xy, xy, sizeof xy);
    a->sec = (sm_section){7e10, 4e-4, 2e-7, 1.2};
    a->mem[0] = (sm_member){0, 1, 0, e1};
    a->mem[1] = (sm_member){1, 2, 0, e2};
    memset(&a->st, 0, sizeof a->st);
    a->st.n_joints = 3;
    a->st.joint_xy = a->xy;
    a->st.n_sections = 1;
    a->st.sections = &a->sec;
    a->st.n_members = 2;
    a->st.members = a->mem;
    a->st.clamp = 0;
}

/* Solve one speed; returns the result or NULL (and prints why). */
static inline sm_result *tu_solve1(const sm_structure *st, const sm_options *o, double omega,
                                   sm_model **mout)
{
    sm_model *m = NULL;
    sm_result *r = NULL;
    sm_diag d;
    if (sm_model_new(&m, st, o, &d) < 0) {
        printf("model: %s\n", d.message);
        return NULL;
    }
    if (sm_solve(m, &omega, 1, NULL, NULL, &r, &d) < 0) {
        printf("solve: %s\n", d.message);
        sm_model_free(m);
        return NULL;
    }
    if (mout)
        *mout = m;
    else
        sm_model_free(m);
    return r;
}

/* Read a numeric CSV cell by header name from line `row` (0-based, data rows
 * after the header; '#' lines skipped).  Returns NAN when absent. */
typedef struct tu_csv {
    int rows, cols;
    char **head;
    char ***cell;
} tu_csv;

static inline void tu_csv_free(tu_csv *c)
{
    for (int j = 0; j < c->cols; j++)
        free(c->head[j]);
    free(c->head);
    for (int i = 0; i < c->rows; i++) {
        for (int j = 0; j < c->cols; j++)
            free(c->cell[i][j]);
        free(c->cell[i]);
    }
    free(c->cell);
}

static inline int tu_csv_split(char *line, char **out, int max)
{
    int n = 0;
    char *save = NULL;
    line[strcspn(line, "\r\n")] = 0;
    for (char *t = strtok_r(line, ",", &save); t && n < max; t = strtok_r(NULL, ",", &save))
        out[n++] = t;
    return n;
}

static inline int tu_csv_read(const char *path, tu_csv *c)
{
    FILE *f = fopen(path, "r");
    char line[4096], *tok[64];
    memset(c, 0, sizeof *c);
    if (!f) {
        printf("cannot open %s\n", path);
        return -1;
    }
    while (fgets(line, sizeof line, f)) {
        if (line[0] == '#' || line[0] == '\n')
            continue;
        int n = tu_csv_split(line, tok, 64);
        if (!c->head) {
            c->cols = n;
            c->head = calloc((size_t)n, sizeof(char *));
            for (int j = 0; j < n; j++)
                c->head[j] = strdup(tok[j]);
            continue;
        }
        c->cell = realloc(c->cell, (size_t)(c->rows + 1) * sizeof(char **));
        c->cell[c->rows] = calloc((size_t)c->cols, sizeof(char *));
        for (int j = 0; j < c->cols; j++)
            c->cell[c->rows][j] = strdup(j < n ? tok[j] : "");
        c->rows++;
    }
    fclose(f);
    return 0;
}

/* Read reference file `name` from the directory given as argv[1] (meson
 * passes tests/reference), or from "." when absent. */
static inline int tu_ref_read(int argc, char **argv, const char *name, tu_csv *c)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", argc > 1 ? argv[1] : ".", name);
    return tu_csv_read(path, c);
}

static inline const char *tu_csv_get(const tu_csv *c, int row, const char *col)
{
    for (int j = 0; j < c->cols; j++)
        if (!strcmp(c->head[j], col))
            return c->cell[row][j];
    return "";
}

static inline double tu_csv_num(const tu_csv *c, int row, const char *col)
{
    const char *s = tu_csv_get(c, row, col);
    char *end;
    double v = strtod(s, &end);
    return end == s ? NAN : v;
}

#endif
