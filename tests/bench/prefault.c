/*
 * prefault.so — an LD_PRELOAD experiment (issue 27 goal 1), not part of spinmodal: before main,
 * keep glibc's heap (no trim; blocks up to 32 MB from the heap, not mmap) and grow it by
 * PREFAULT_MB (default 2) MB whose pages are faulted in at once (MADV_POPULATE_WRITE; where the
 * kernel lacks it, or with PREFAULT_HOW=t, page by page; PREFAULT_HOW=n only keeps the heap).  If
 * a small solve is faster with it on a machine, its heap's first-touch faults are worth cutting
 * there.  Used by tests/bench/bench_faults.sh.
 */
#define _DEFAULT_SOURCE
#include <malloc.h>
#include <stdint.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <unistd.h>
#ifndef MADV_POPULATE_WRITE
#define MADV_POPULATE_WRITE 23
#endif

__attribute__((constructor(101))) static void prefault(void)
{
    const char *e = getenv("PREFAULT_MB"), *how = getenv("PREFAULT_HOW");
    size_t mb = e ? strtoul(e, NULL, 10) : 2;
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
    mallopt(M_TRIM_THRESHOLD, 512 << 20);
    char *lo = sbrk(0);
    void *volatile p = malloc(mb << 20); /* the heap grows by mb MB; volatile: not elided */
    char *hi = sbrk(0);
    free(p);
    if ((how && *how == 'n') || hi <= lo)
        return;
    uintptr_t a = ((uintptr_t)lo + 4095) & ~(uintptr_t)4095;
    if ((how && *how == 't') ||
        madvise((void *)a, (size_t)(hi - (char *)a), MADV_POPULATE_WRITE) != 0)
        for (char *q = (char *)a; q < hi; q += 4096)
            *(volatile char *)q = 0;
}
