/* cpu.h - which instruction set the kernels of egofuse use.
 *
 * One scalar reference defines every kernel's result; the SIMD paths give
 * the same bytes. This module only picks the path: the best one the CPU
 * has, capped by the caller (a desc's max_isa) and by the environment
 * variable EGOFUSE_ISA = ref | sse2 | avx2 | avx512. The CPU feature word
 * is the only process-wide value in egofuse; it is read-only after the
 * first call (reading it twice gives the same answer, so the race is
 * benign).
 *
 *   ef_isa isa = ef_isa_choose(EF_ISA_DEFAULT);   // cpuid, capped by env
 *   printf("using %s\n", ef_isa_name(isa));
 */
#ifndef EGOFUSE_CPU_H
#define EGOFUSE_CPU_H

#ifdef __cplusplus
extern "C" {
#endif

typedef enum ef_isa {
    EF_ISA_DEFAULT = 0,   /* as a cap: no cap (the best available) */
    EF_ISA_REF,           /* the scalar reference */
    EF_ISA_SSE2,          /* x86-64 baseline (or NEON on ARM: portable) */
    EF_ISA_AVX2,          /* AVX2 (+F16C) */
    EF_ISA_AVX512,        /* AVX-512 F, BW, DQ, VL */
    EF_ISA_COUNT
} ef_isa;

/* The best ISA this CPU (and OS) runs. */
ef_isa ef_cpu_best(void);
/* 1 if this CPU runs isa. */
int ef_cpu_has(ef_isa isa);
/* The ISA to use: min(best, cap, EGOFUSE_ISA). An unknown EGOFUSE_ISA
 * value is ignored (ef_isa_env_error() says so). */
ef_isa ef_isa_choose(ef_isa cap);
/* "ref", "sse2", "avx2", "avx512" ("default" for EF_ISA_DEFAULT). */
const char *ef_isa_name(ef_isa isa);
/* Parses a name; returns EF_ISA_DEFAULT for an unknown one. */
ef_isa ef_isa_parse(const char *name);
/* The EGOFUSE_ISA value when it is set but not a known name, else NULL. */
const char *ef_isa_env_error(void);

#ifdef __cplusplus
}
#endif
#endif
