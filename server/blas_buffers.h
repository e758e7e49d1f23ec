/*
 * blas_buffers.h — OpenBLAS work buffers kept per thread (blas_buffers.c): linked into both
 * programs with -Wl,--wrap=blas_memory_alloc,--wrap=blas_memory_free where OpenBLAS comes from
 * its archive (server/meson.build).  Nothing to call: these two report, for tests and benches.
 */
#ifndef SPINMODAL_BLAS_BUFFERS_H
#define SPINMODAL_BLAS_BUFFERS_H

/** Buffers the calling thread keeps now (0 .. 2). */
int blas_buffers_held(void);

/** Buffers taken from OpenBLAS and not yet given back, all threads together: a thread keeps at
 * most 2 and gives them back when it ends. */
int blas_buffers_out(void);

#endif
