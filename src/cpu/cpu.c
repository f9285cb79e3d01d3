/* cpu.c - CPU feature detection and the ISA cap. */
#include "cpu.h"

/* Big-endian machines: not supported. The SIMD paths are x86's and NEON's, and the
 * byte-for-byte claims (README, docs/portability.md) were checked on
 * little-endian x86-64 and ARM64 only; the build refuses rather than give
 * bytes nobody compared. EGOFUSE_ALLOW_BIG_ENDIAN builds it anyway. */
#if defined(__BYTE_ORDER__) && defined(__ORDER_BIG_ENDIAN__) && \
    __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__ && !defined(EGOFUSE_ALLOW_BIG_ENDIAN)
#error "egofuse: big-endian targets are not supported (checked on little-endian x86-64 and ARM64 only, see README); -DEGOFUSE_ALLOW_BIG_ENDIAN builds it anyway, unchecked"
#endif

#include <stdlib.h>
#include <string.h>

static const char *names[EF_ISA_COUNT] = {"default", "ref", "sse2", "avx2", "avx512", "neon"};
static const int levels[EF_ISA_COUNT] = {3, 0, 1, 2, 3, 1};

static ef_isa detect(void)
{
#if defined(__x86_64__) || defined(__i386__)
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
        __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl") &&
        __builtin_cpu_supports("avx2"))
        return EF_ISA_AVX512;
    if (__builtin_cpu_supports("avx2")) return EF_ISA_AVX2;
    if (__builtin_cpu_supports("sse2")) return EF_ISA_SSE2;
    return EF_ISA_REF;
#elif defined(__aarch64__) && defined(__ARM_NEON)
    return EF_ISA_NEON; /* Advanced SIMD is part of every AArch64 CPU */
#else
    return EF_ISA_REF;
#endif
}

ef_isa ef_cpu_best(void)
{
    static volatile int cached = -1; /* the one process-wide value */
    if (cached < 0) cached = (int)detect();
    return (ef_isa)cached;
}

/* The ISAs of this architecture, in level order. */
#if defined(__x86_64__) || defined(__i386__)
#define ARCH_ISAS { EF_ISA_REF, EF_ISA_SSE2, EF_ISA_AVX2, EF_ISA_AVX512 }
#elif defined(__aarch64__) && defined(__ARM_NEON)
#define ARCH_ISAS { EF_ISA_REF, EF_ISA_NEON }
#else
#define ARCH_ISAS { EF_ISA_REF }
#endif
static const ef_isa arch_isas[] = ARCH_ISAS;
#define ARCH_N ((int)(sizeof arch_isas / sizeof arch_isas[0]))

int ef_isa_level(ef_isa isa)
{
    return (unsigned)isa < EF_ISA_COUNT ? levels[isa] : 3;
}

int ef_cpu_has(ef_isa isa)
{
    if (isa == EF_ISA_DEFAULT || (unsigned)isa >= EF_ISA_COUNT) return 0;
    const int best = ef_isa_level(ef_cpu_best());
    for (int i = 0; i < ARCH_N; i++)
        if (arch_isas[i] == isa) return levels[isa] <= best;
    return 0;
}

ef_isa ef_cpu_cap(ef_isa cap)
{
    const int lim = ef_isa_level(cap), best = ef_isa_level(ef_cpu_best());
    ef_isa r = EF_ISA_REF;
    for (int i = 0; i < ARCH_N; i++)
        if (levels[arch_isas[i]] <= lim && levels[arch_isas[i]] <= best) r = arch_isas[i];
    return r;
}

const char *ef_isa_name(ef_isa isa)
{
    return (unsigned)isa < EF_ISA_COUNT ? names[isa] : "unknown";
}

ef_isa ef_isa_parse(const char *name)
{
    if (!name) return EF_ISA_DEFAULT;
    for (int i = 1; i < EF_ISA_COUNT; i++)
        if (!strcmp(name, names[i])) return (ef_isa)i;
    return EF_ISA_DEFAULT;
}

const char *ef_isa_env_error(void)
{
    const char *e = getenv("EGOFUSE_ISA");
    if (!e || !*e) return NULL;
    return ef_isa_parse(e) == EF_ISA_DEFAULT ? e : NULL;
}

ef_isa ef_isa_choose(ef_isa cap)
{
    ef_isa env = ef_isa_parse(getenv("EGOFUSE_ISA"));
    if (env != EF_ISA_DEFAULT && ef_isa_level(env) < ef_isa_level(cap)) cap = env;
    return ef_cpu_cap(cap);
}

void ef_cpu_relax(void)
{
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#elif defined(__aarch64__)
    __asm__ __volatile__("yield");
#endif
}
