/* hugepages.c — aligned, huge-page-advised mappings for the engine's large arrays (hugepages.h). */
#define _DEFAULT_SOURCE /* MAP_ANONYMOUS, madvise, MADV_HUGEPAGE */
#include "hugepages.h"

#include <stdint.h>
#include <sys/mman.h>
#include <unistd.h>

#if defined(__SANITIZE_ADDRESS__)
/* Under AddressSanitizer the blocks come from calloc, whose bounds it checks. */
#include <stdlib.h>
void *jd_huge_alloc(size_t bytes) { return calloc(bytes ? bytes : 1, 1); }
void jd_huge_free(void *p, size_t bytes) {
    (void)bytes;
    free(p);
}
#else
#define HUGE_PAGE ((size_t)2 << 20) /* x86-64's PMD-sized transparent huge page */

static size_t round_up(size_t a, size_t to) { return (a + to - 1) / to * to; }

/* The size of the mapping jd_huge_alloc(bytes) makes (and jd_huge_free unmaps): from half a
 * huge page on, whole huge pages (at 80k particles the lists' index arrays are 1.2 MB; on huge
 * pages the pair loop's median was 3-6 % lower, docs/performance.md), else whole pages. */
static size_t mapped_size(size_t bytes) {
    return bytes >= HUGE_PAGE / 2 ? round_up(bytes, HUGE_PAGE)
                              : round_up(bytes ? bytes : 1, (size_t)sysconf(_SC_PAGESIZE));
}

static void *map(size_t size) {
    void *p = mmap(NULL, size, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    return p == MAP_FAILED ? NULL : p;
}

void *jd_huge_alloc(size_t bytes) {
    const size_t size = mapped_size(bytes);
    if (size < HUGE_PAGE) return map(size);
    /* map a huge page more, then give back the unaligned head and the tail */
    char *raw = map(size + HUGE_PAGE);
    if (!raw) return NULL;
    char *p = (char *)round_up((uintptr_t)raw, HUGE_PAGE);
    if (p > raw) munmap(raw, (size_t)(p - raw));
    munmap(p + size, HUGE_PAGE - (size_t)(p - raw));
    (void)madvise(p, size, MADV_HUGEPAGE); /* a hint: without it the pages are 4 KiB */
    return p;
}

void jd_huge_free(void *p, size_t bytes) {
    if (p) munmap(p, mapped_size(bytes));
}
#endif
