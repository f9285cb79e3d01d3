/* isa_skip.h - the skip of a per-ISA test on a CPU that does not run that
 * ISA (test_raster_records.c, test_raster_xform.c): reported as SKIP
 * (cmocka skip()), never as a pass, with what goes untested.
 * Header-only (static inline); include after support/testutil.h,
 * <cmocka.h> and src/cpu/cpu.h. */
#ifndef EGOFUSE_TU_ISA_SKIP_H
#define EGOFUSE_TU_ISA_SKIP_H

/* Returns when this CPU runs isa; else prints "SKIP <isa>: not supported
 * by this CPU; untested: <untested>" and skips the test. */
static inline void tu_skip_unless_isa(ef_isa isa, const char *untested)
{
    if (ef_cpu_has(isa)) return;
    print_message("SKIP %s: not supported by this CPU; untested: %s\n", ef_isa_name(isa),
                  untested);
    skip();
}

#endif
