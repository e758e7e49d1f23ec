/*
 * cpuid_cost — what one CPUID instruction costs on this machine (issue 27 goal 1, DESIGN.md
 * §2.1): a virtual machine traps it, and every process start runs a few dozen (glibc's ld.so
 * detects the CPU; before 0.8.8 libgfortran's and libgcc_s's constructors added theirs: 8.3 us
 * each on the 2-core machine here).  1 000 CPUIDs of leaf 7 in a loop, timed.  A benchmark, never
 * a test; on a CPU without CPUID (not x86) it says so.
 *   build/tests/bench/cpuid_cost
 */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <time.h>
#if defined(__x86_64__) || defined(__i386__)
#include <cpuid.h>
#endif

int main(void)
{
#if defined(__x86_64__) || defined(__i386__)
    enum { N = 1000 };
    struct timespec a, b;
    unsigned r[4] = {0};
    clock_gettime(CLOCK_MONOTONIC, &a);
    for (int i = 0; i < N; i++) {
        __cpuid_count(7, 0, r[0], r[1], r[2], r[3]);
        __asm__ volatile("" : : "r"(r[1]) : "memory"); /* keep each one */
    }
    clock_gettime(CLOCK_MONOTONIC, &b);
    double us = ((double)(b.tv_sec - a.tv_sec) * 1e9 + (double)(b.tv_nsec - a.tv_nsec)) / 1e3 / N;
    printf("cpuid: %.2f us each (%d in a loop; leaf 7 ebx %#x)\n", us, N, r[1]);
#else
    printf("cpuid: not an x86 CPU\n");
#endif
    return 0;
}
