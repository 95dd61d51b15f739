/*
 * test_hugepages.c — the engine's block allocator (stepper/hugepages.h) against its contract:
 * the block is zeroed and writable over all the bytes asked for; from 1 MiB on it starts on a
 * 2 MiB boundary; and where the kernel offers transparent huge pages ("always" or "madvise" in
 * /sys/kernel/mm/transparent_hugepage/enabled), a written 4 MiB block is backed by them
 * (AnonHugePages of its mapping in /proc/self/smaps).  AddressSanitizer builds take the blocks
 * from calloc (hugepages.c), so only the first part applies there.
 */
#include "unit.h"

#include <stdio.h>
#include <string.h>

#include "hugepages.h"

#define MIB ((size_t)1 << 20)

static void zeroed_and_writable(void **state) {
    (void)state;
    const size_t sizes[] = {0, 1, 4095, 4096, MIB - 1, MIB, 3 * MIB + 5};
    for (size_t k = 0; k < sizeof sizes / sizeof *sizes; k++) {
        unsigned char *p = jd_huge_alloc(sizes[k]);
        assert_non_null(p);
        for (size_t b = 0; b < sizes[k]; b++)
            if (p[b]) fail_msg("byte %zu of a block of %zu is %d, not 0", b, sizes[k], p[b]);
        memset(p, 0xa5, sizes[k]);
        if (sizes[k]) assert_int_equal(p[sizes[k] - 1], 0xa5);
        jd_huge_free(p, sizes[k]);
    }
    jd_huge_free(NULL, 10); /* like free(NULL) */
}

#if !defined(__SANITIZE_ADDRESS__)
static void large_blocks_start_on_a_huge_page(void **state) {
    (void)state;
    const size_t sizes[] = {MIB, 2 * MIB, 5 * MIB + 3};
    for (size_t k = 0; k < sizeof sizes / sizeof *sizes; k++) {
        void *p = jd_huge_alloc(sizes[k]);
        assert_non_null(p);
        assert_int_equal((uintptr_t)p % (2 * MIB), 0);
        jd_huge_free(p, sizes[k]);
    }
}

/* The kB of AnonHugePages of the mapping of /proc/self/smaps that contains p, or -1. */
static long anon_huge_kb(const void *p) {
    FILE *f = fopen("/proc/self/smaps", "r");
    if (!f) return -1;
    char line[512];
    int inside = 0;
    long kb = -1;
    while (fgets(line, sizeof line, f)) {
        unsigned long lo, hi;
        if (sscanf(line, "%lx-%lx ", &lo, &hi) == 2 && strchr(line, '-') < strchr(line, ' '))
            inside = (uintptr_t)p >= lo && (uintptr_t)p < hi;
        else if (inside && sscanf(line, "AnonHugePages: %ld kB", &kb) == 1)
            break;
    }
    fclose(f);
    return kb;
}

static void written_blocks_get_huge_pages(void **state) {
    (void)state;
    FILE *f = fopen("/sys/kernel/mm/transparent_hugepage/enabled", "r");
    char mode[128] = "";
    if (f) {
        if (!fgets(mode, sizeof mode, f)) mode[0] = '\0';
        fclose(f);
    }
    if (!strstr(mode, "[always]") && !strstr(mode, "[madvise]")) skip(); /* no THP here */
    const size_t bytes = 4 * MIB;
    unsigned char *p = jd_huge_alloc(bytes);
    assert_non_null(p);
    memset(p, 1, bytes);
    const long kb = anon_huge_kb(p);
    jd_huge_free(p, bytes);
    if (kb <= 0) fail_msg("a written 4 MiB block has %ld kB of huge pages (THP mode: %s)", kb, mode);
}
#endif

int run_hugepages_tests(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(zeroed_and_writable),
#if !defined(__SANITIZE_ADDRESS__)
        cmocka_unit_test(large_blocks_start_on_a_huge_page),
        cmocka_unit_test(written_blocks_get_huge_pages),
#endif
    };
    return cmocka_run_group_tests_name("hugepages", tests, NULL, NULL);
}
