/* ef_mem.h - freeing a struct's buffers in one call.
 *
 * WHAT IT DOES: EF_FREE_ALL(a, b, c) frees each pointer it is given (NULL
 * ones too, as free does), in the order given. Destructors of structs that
 * own many buffers name them in one list instead of a column of free calls.
 * WHAT IT DOES NOT: clear the pointers (the destructor memsets its struct
 * after), or work in C++ (it builds a C99 compound literal).
 * USAGE:
 *   EF_FREE_ALL(r->depth, r->nrm, r->mask);
 *   memset(r, 0, sizeof *r);
 */
#ifndef EGOFUSE_EF_MEM_H
#define EGOFUSE_EF_MEM_H

#include <stddef.h>
#include <stdlib.h>

static inline void ef_free_n(void *const *p, size_t n)
{
    for (size_t i = 0; i < n; i++)
        free(p[i]);
}

#define EF_FREE_ALL(...)                                                  \
    ef_free_n((void *const[]){__VA_ARGS__},                               \
              sizeof((void *const[]){__VA_ARGS__}) / sizeof(void *))

#endif
