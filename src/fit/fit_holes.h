#ifndef EGOFUSE_FIT_HOLES_H
#define EGOFUSE_FIT_HOLES_H
/* Small holes and islands of a refined mask (issue 14 item 2,
 * docs/accuracy.md "Where the boundary misses"). The band refinement
 * decides each band pixel by colour and a 3x3 vote; shadowed skin inside
 * the palm or between the fingers falls below the vote as holes of a few
 * to a few hundred pixels, and single background specks come in as
 * islands. Every hole is an edge of the mask far from the true edge:
 * boundary F (3 px) counts it against the method. */
#include <stddef.h>
#include <stdint.h>

/* Bytes of scratch that pipe_fit_fill_small needs for a width x height
 * mask in the worst case (every row alternating); 0 for bad sizes. */
size_t pipe_fit_fill_scratch_size(int width, int height);

/* Fills the holes (4-connected components of mask < 128 that touch no
 * image border) of at most max_hole pixels with 255, and clears the
 * islands (4-connected components of mask >= 128 that touch no image
 * border) of at most max_island pixels to 0; both decided on the mask as
 * given (a component is a hole or an island of the input). inside (not
 * NULL, inside_stride): a hole is filled only if every pixel of it is set
 * (>= 128) in inside, the kinematic mask (a gap the model has too, a cup
 * held in the fingers, stays open). max_hole or
 * max_island 0: that half is off. Returns the pixels changed, or -1 (the
 * mask unchanged) for bad arguments or when scratch_size is too small for
 * the mask's runs (pipe_fit_fill_scratch_size always suffices). */
long pipe_fit_fill_small(uint8_t *mask, int stride, int width, int height, int max_hole,
                         int max_island, const uint8_t *inside, int inside_stride, void *scratch,
                         size_t scratch_size);
#endif
