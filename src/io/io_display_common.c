/* io_display_common.c - what the display backends (io_display_kms.c,
 * io_display_sdl.c) share: the clock, the queue of flips and the RGBA ->
 * XRGB blit (declared in io_display_impl.h). It calls no backend, so the
 * backends and the dispatcher above them (io_display.c) form no circle. */
#include "io_display_impl.h"

#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

uint64_t io_display_now_ns(void)
{
    return io_now_ns();
}

void io_display_push_flip(io_display *d, uint64_t frame_id, uint64_t t_ns, uint32_t seq)
{
    if (d->qlen == IO_DISPLAY_QUEUE) {
        d->qhead = (d->qhead + 1) % IO_DISPLAY_QUEUE;
        d->qlen--;
    }
    io_display_flip *f = &d->q[(d->qhead + d->qlen) % IO_DISPLAY_QUEUE];
    f->frame_id = frame_id;
    f->t_ns = t_ns;
    f->seq = seq;
    d->qlen++;
}

void io_display_blit_xrgb(uint8_t *dst, size_t dst_pitch, int x0, int y0, const uint8_t *src,
                          size_t stride, int w, int h)
{
    for (int y = 0; y < h; y++) {
        const uint8_t *s = src + (size_t)y * stride;
        uint32_t *o = (uint32_t *)(dst + (size_t)(y0 + y) * dst_pitch) + x0;
        /* a little-endian word R | G << 8 | B << 16 | A << 24 becomes
         * B | G << 8 | R << 16: swap R and B, drop A */
        int x = 0;
#if defined(__SSE2__)
        const __m128i lo = _mm_set1_epi32(0xff), mid = _mm_set1_epi32(0xff00);
        for (; x + 4 <= w; x += 4) {
            __m128i v = _mm_loadu_si128((const __m128i *)(s + 4 * (size_t)x));
            __m128i r = _mm_or_si128(_mm_slli_epi32(_mm_and_si128(v, lo), 16),
                                     _mm_or_si128(_mm_and_si128(v, mid),
                                                  _mm_and_si128(_mm_srli_epi32(v, 16), lo)));
            _mm_storeu_si128((__m128i *)(o + x), r);
        }
#endif
        for (; x < w; x++) {
            uint32_t v;
            memcpy(&v, s + 4 * (size_t)x, 4);
            o[x] = ((v & 0xffu) << 16) | (v & 0xff00u) | ((v >> 16) & 0xffu);
        }
    }
}
