/*
 * blas_buffers.c — each thread keeps the OpenBLAS work buffer it used last (issue 27 goal 4,
 * DESIGN.md §2.1).
 *
 * Every OpenBLAS call that packs or copies (the level-2 and level-3 interfaces, its own LU and
 * Cholesky) takes a work buffer with blas_memory_alloc and hands it back with blas_memory_free.
 * Debian's OpenBLAS 0.3.21 (built without USE_TLS) keeps one table of buffers per process behind
 * one mutex: three lock round trips a call, and a first-fit search that gives the lowest free
 * buffer to whichever thread asks, so with many threads each call packs into memory another core
 * wrote last.  An 11-speed planar job makes about 5 300 such calls (dsymv and dtrmv inside
 * dsyevr's reduction); with 16 workers in one daemon each job took 128-133 ms of CPU against
 * 102-108 ms with this file (the 16-core device, two alternated runs; separate processes, each
 * with its own table, do not have the cost).
 *
 * Both programs link OpenBLAS from its archive with -Wl,--wrap for the two symbols
 * (server/meson.build), so every call inside OpenBLAS comes here.  A thread keeps up to
 * BLAS_KEEP buffers it handed back and reuses them; it takes from OpenBLAS only when it holds
 * none, and gives its buffers back to OpenBLAS when it ends (a thread-specific destructor), so
 * short-lived threads (a sweep's pool) do not use up OpenBLAS's table.  The buffers are
 * OpenBLAS's own (the same size and alignment), so every result is bit for bit what it was.
 * Thread-local state is what this needs: it replaces state OpenBLAS already keeps per process.
 * Where the thread-specific key cannot be made, nothing is kept (OpenBLAS's own behaviour).
 */
#include "blas_buffers.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stddef.h>

/* OpenBLAS (driver/others/memory.c); --wrap makes the real ones __real_*. */
void *__real_blas_memory_alloc(int procpos);
void __real_blas_memory_free(void *buffer);
void *__wrap_blas_memory_alloc(int procpos);
void __wrap_blas_memory_free(void *buffer);

/* Buffers a thread keeps: one call holds one at a time; a second covers a nested one. */
#define BLAS_KEEP 2

typedef struct blas_kept {
    int n;          /* buffers held, buf[0 .. n) */
    int registered; /* 1: the destructor gives them back; -1: could not register, keep none */
    void *buf[BLAS_KEEP];
} blas_kept;

static _Thread_local blas_kept blas_tl;
static pthread_key_t blas_key;
static pthread_once_t blas_once = PTHREAD_ONCE_INIT;
static int blas_key_made;
static atomic_int blas_out; /* buffers taken from OpenBLAS and not given back (blas_buffers_out) */

/* A thread ends: its buffers go back to OpenBLAS's table. */
static void blas_give_back(void *p)
{
    blas_kept *k = p;
    while (k->n > 0) {
        __real_blas_memory_free(k->buf[--k->n]);
        atomic_fetch_sub(&blas_out, 1);
    }
}

static void blas_make_key(void)
{
    blas_key_made = pthread_key_create(&blas_key, blas_give_back) == 0;
}

/* 1 when this thread may keep buffers (its destructor is registered). */
static int blas_may_keep(void)
{
    if (blas_tl.registered == 0) {
        pthread_once(&blas_once, blas_make_key);
        blas_tl.registered = blas_key_made && pthread_setspecific(blas_key, &blas_tl) == 0 ? 1 : -1;
    }
    return blas_tl.registered == 1;
}

void *__wrap_blas_memory_alloc(int procpos)
{
    if (blas_tl.n > 0)
        return blas_tl.buf[--blas_tl.n];
    void *buffer = __real_blas_memory_alloc(procpos);
    if (buffer)
        atomic_fetch_add(&blas_out, 1);
    return buffer;
}

void __wrap_blas_memory_free(void *buffer)
{
    if (buffer && blas_tl.n < BLAS_KEEP && blas_may_keep()) {
        blas_tl.buf[blas_tl.n++] = buffer;
        return;
    }
    __real_blas_memory_free(buffer);
    if (buffer)
        atomic_fetch_sub(&blas_out, 1);
}

int blas_buffers_held(void)
{
    return blas_tl.n;
}

int blas_buffers_out(void)
{
    return atomic_load(&blas_out);
}
