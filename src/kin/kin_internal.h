/* kin_internal.h - helpers shared by the kin sources (not a public API). */
#ifndef EGOFUSE_KIN_INTERNAL_H
#define EGOFUSE_KIN_INTERNAL_H

#include <stddef.h>
#include <string.h>

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
/* A strict decimal number (kin__parse_number) kept as a float of magnitude
 * at most 1e30: 0, -1 for no number, -2 out of range. The float is
 * checked, not the parsed double: "1000000000000000000084467440731" is 1e30
 * as a double but 1e30f = 1.00000002e30 as a float, which a writer of 9
 * digits then writes past a double check (fuzz_kin_calib's find): every
 * value this accepts formats to one it accepts again. */
int kin__parse_float(const char *tok, float *out);

/* Splits a line in place into tokens separated by spaces, tabs and CRs,
 * up to a '#' comment (each token NUL-terminated, tok[] pointing into
 * buf); the number of tokens, or -1 when there are more than cap. The
 * line formats of kin_calib.c and kin_track.c. */
int kin__tokens(char *buf, char **tok, int cap);

/* One line of those formats split into tokens: copies line[0, len) into
 * buf (the caller has checked that len < the size of buf), terminates it
 * and splits it with kin__tokens. The number of tokens, or -1 with
 * *reason set ("NUL byte in line", "too many fields"). */
int kin__line_tokens(const char *line, size_t len, char *buf, char **tok, int cap,
                     const char **reason);

struct kin_channel;
/* The value of an animation channel at time t (kin_anim.c): ch->comps
 * floats into out; clamped to the first and last key, STEP, LINEAR
 * (slerp for rotations, not renormalised), CUBICSPLINE (glTF appendix
 * C). The caller has checked key_count >= 1, times and values. */
void kin__channel_value(const struct kin_channel *ch, float t, float *out);

/* The next line of text[0, len) at *pos: its start (NULL at the end), its
 * length without the '\n' in *l; *pos moves past it. The line formats of
 * kin_calib.c and kin_track.c. */
static inline const char *kin__next_line(const char *text, size_t len, size_t *pos, size_t *l)
{
    if (*pos >= len) return NULL;
    const char *ln = text + *pos;
    const char *nl = memchr(ln, '\n', len - *pos);
    *l = nl ? (size_t)(nl - ln) : len - *pos;
    *pos += *l + (nl ? 1 : 0);
    return ln;
}

#endif
