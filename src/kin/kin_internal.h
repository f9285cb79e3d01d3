/* kin_internal.h - helpers shared by the kin sources (not a public API). */
#ifndef EGOFUSE_KIN_INTERNAL_H
#define EGOFUSE_KIN_INTERNAL_H

#include <stddef.h>

#if defined(__GNUC__)
#define KIN__PRINTF(f, a) __attribute__((format(printf, f, a)))
#else
#define KIN__PRINTF(f, a)
#endif

/* Writes a printf-style reason into why[n] (when why and n are non-zero)
 * and returns ret: `return kin__fail(why, n, -1, "joint %d ...", j);`. */
int kin__fail(char *why, size_t n, int ret, const char *fmt, ...) KIN__PRINTF(4, 5);

/* Text output with snprintf semantics: writes what fits into buf[size]
 * (always terminated when size > 0) and counts in len the length the
 * whole text needs, so a caller can ask again with a larger buffer. */
typedef struct kin__sink { char *buf; size_t size, len; } kin__sink;
void kin__put(kin__sink *k, const char *fmt, ...) KIN__PRINTF(2, 3);

/* A strict decimal number, the whole token: [+-]digits[.digits] or
 * [+-].digits, optional exponent; no hex, inf or nan. Returns 0 and the
 * finite value, or -1. */
int kin__parse_number(const char *tok, double *out);

#endif
