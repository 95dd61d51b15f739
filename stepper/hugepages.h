/*
 * hugepages.h — memory for the engine's large arrays, on transparent huge pages.
 *
 * Beds of 80k particles and more do not fit in the cache, and with 4 KiB pages their streams
 * also miss the TLB.  The kernel backs a mapping with 2 MiB pages where it is advised to
 * (MADV_HUGEPAGE; Debian's default THP mode is "madvise"), but only pages first touched after
 * the advice, in 2 MiB-aligned stretches.  Memory from malloc is often neither: after the scene
 * reader's frees glibc serves large blocks from heap pages the reader already wrote.  So the
 * per-particle arrays share one mapping of their own, aligned and advised before it is written
 * (sim.c, alloc_particle_arrays), and each array of the contact lists has one (neighbour.c,
 * list_resize).  Measured in docs/performance.md.
 */
#ifndef JD_HUGEPAGES_H
#define JD_HUGEPAGES_H

#include <stddef.h>

/* A zeroed mapping of at least `bytes` bytes, or NULL when the system has no memory for it.
 * From 1 MiB on it is 2 MiB-aligned, a whole number of 2 MiB pages, and advised for huge pages
 * (a hint: where the kernel does not follow it, the mapping has 4 KiB pages).  AddressSanitizer
 * builds take the memory from calloc instead, so that their bounds are checked. */
void *jd_huge_alloc(size_t bytes);

/* Give back what jd_huge_alloc(bytes) returned (p may be NULL). */
void jd_huge_free(void *p, size_t bytes);

#endif
