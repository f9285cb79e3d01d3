/* pipe_soft.c - soft silhouettes from a binary mask (pipe_soft.h). */
#include "pipe_soft.h"
#include "../cpu/mask_rows.h"

#include <string.h>

void pipe__soft_edge(const uint8_t *mask, uint8_t *out, int w, int h, const int box[4])
{
    const int x0 = box ? box[0] : 0, y0 = box ? box[1] : 0;
    const int x1 = box ? box[2] : w, y1 = box ? box[3] : h;
    for (int y = y0; y < y1; y++) {
        const uint8_t *m = mask + (size_t)y * (size_t)w;
        const uint8_t *u = y > 0 ? m - w : NULL, *d = y + 1 < h ? m + w : NULL;
        uint8_t *o = out + (size_t)y * (size_t)w;
        for (int x = x0; x < x1; x++) {
            /* 8 at a time: all clear, or all 255 with their neighbours */
            if (x + 8 <= x1) {
                uint64_t a;
                memcpy(&a, m + x, 8);
                if (a == 0) {
                    memset(o + x, 0, 8);
                    x += 7;
                    continue;
                }
                if (u && d && x >= 1 && x + 9 <= w) {
                    uint64_t r[6];
                    memcpy(&r[0], u + x - 1, 8);
                    memcpy(&r[1], u + x + 1, 8);
                    memcpy(&r[2], m + x - 1, 8);
                    memcpy(&r[3], m + x + 1, 8);
                    memcpy(&r[4], d + x - 1, 8);
                    memcpy(&r[5], d + x + 1, 8);
                    if ((r[0] & r[1] & r[2] & r[3] & r[4] & r[5]) == ~(uint64_t)0) {
                        memcpy(o + x, m + x, 8);
                        x += 7;
                        continue;
                    }
                }
            }
            if (m[x] == 0) {
                o[x] = 0;
                continue;
            }
            int n = 0;
            for (int dx = -1; dx <= 1; dx++) {
                const int xx = x + dx;
                if (xx < 0 || xx >= w) {
                    n += 3;
                    continue;
                }
                n += (u ? u[xx] != 0 : 1) + (m[xx] != 0) + (d ? d[xx] != 0 : 1);
            }
            o[x] = n == 9 ? m[x] : (uint8_t)(((unsigned)m[x] * (unsigned)n + 4u) / 9u);
        }
    }
}

void pipe__soft_edge_boxed(const uint8_t *mask, uint8_t *out, int w, int h, int held[4])
{
    /* the box of the set pixels ({0, 0, 0, 0}: none) */
    int b[4];
    ef_mask_box(mask, w, h, b);
    /* what the held box has outside the new one */
    for (int y = held[1]; y < held[3]; y++) {
        uint8_t *o = out + (size_t)y * (size_t)w;
        if (y < b[1] || y >= b[3] || b[0] >= b[2]) {
            memset(o + held[0], 0, (size_t)(held[2] - held[0]));
            continue;
        }
        const int l = b[0] < held[2] ? b[0] : held[2];
        if (l > held[0]) memset(o + held[0], 0, (size_t)(l - held[0]));
        const int r = b[2] > held[0] ? b[2] : held[0];
        if (held[2] > r) memset(o + r, 0, (size_t)(held[2] - r));
    }
    if (b[0] < b[2]) pipe__soft_edge(mask, out, w, h, b);
    memcpy(held, b, sizeof b);
}
