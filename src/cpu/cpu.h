/* cpu.h - which instruction set the kernels of egofuse use.
 *
 * One scalar reference defines every kernel's result; the SIMD paths give
 * the same bytes. This module only picks the path: the best one the CPU
 * has, capped by the caller (a desc's max_isa) and by the environment
 * variable EGOFUSE_ISA = ref | sse2 | avx2 | avx512 | neon. The CPU feature word
 * is the only process-wide value in egofuse; it is read-only after the
 * first call (reading it twice gives the same answer, so the race is
 * benign).
 *
 *   ef_isa isa = ef_isa_choose(EF_ISA_DEFAULT);   // cpuid, capped by env
 *   printf("using %s\n", ef_isa_name(isa));
 *
 * Paths of each architecture: x86-64 ref < sse2 < avx2 < avx512; aarch64
 * ref < neon; elsewhere ref. A cap is a LEVEL, not a name, so one cap means
 * the same on every machine: level 0 ref, 1 sse2 or neon (4 lanes), 2
 * avx2, 3 avx512. The path chosen is the best one the CPU runs whose level
 * is at most the cap's: on aarch64 EGOFUSE_ISA=sse2 (or avx2) runs neon and
 * =ref the reference; on x86 EGOFUSE_ISA=neon runs sse2. The vector layer
 * the SIMD kernels are written on: simd.h.
 */
#ifndef EGOFUSE_CPU_H
#define EGOFUSE_CPU_H

#ifdef __cplusplus
extern "C" {
#endif

typedef enum ef_isa {
    EF_ISA_DEFAULT = 0,   /* as a cap: no cap (the best available) */
    EF_ISA_REF,           /* the scalar reference */
    EF_ISA_SSE2,          /* x86-64 baseline */
    EF_ISA_AVX2,          /* AVX2 (+F16C) */
    EF_ISA_AVX512,        /* AVX-512 F, BW, DQ, VL */
    EF_ISA_NEON,          /* AArch64 Advanced SIMD (level of sse2: 4 lanes);
                           * last, so the x86 values keep their numbers */
    EF_ISA_COUNT
} ef_isa;

/* The best ISA this CPU (and OS) runs. */
ef_isa ef_cpu_best(void);
/* 1 if this CPU runs isa (on aarch64: ref and neon; never another
 * architecture's ISA). */
int ef_cpu_has(ef_isa isa);
/* The level of an ISA: ref 0, sse2 and neon 1, avx2 2, avx512 3 (and
 * EF_ISA_DEFAULT or an unknown value: 3, no cap). */
int ef_isa_level(ef_isa isa);
/* The best ISA this CPU runs whose level is at most cap's (EF_ISA_DEFAULT:
 * the best), NOT capped by EGOFUSE_ISA (tests and benchmarks naming a
 * path). */
ef_isa ef_cpu_cap(ef_isa cap);
/* The ISA to use: the best the CPU runs at most at the level of cap and of
 * EGOFUSE_ISA (ef_cpu_cap of the lower). An unknown EGOFUSE_ISA value is
 * ignored (ef_isa_env_error() says so). */
ef_isa ef_isa_choose(ef_isa cap);
/* "ref", "sse2", "avx2", "avx512", "neon" ("default" for EF_ISA_DEFAULT). */
const char *ef_isa_name(ef_isa isa);
/* Parses a name; returns EF_ISA_DEFAULT for an unknown one. */
ef_isa ef_isa_parse(const char *name);
/* The EGOFUSE_ISA value when it is set but not a known name, else NULL. */
const char *ef_isa_env_error(void);

/* One pause of a spin-wait loop (x86 PAUSE, AArch64 YIELD, else nothing):
 * the rooms' thread pools spin through it without intrinsics of their own. */
void ef_cpu_relax(void);

#ifdef __cplusplus
}
#endif
#endif
