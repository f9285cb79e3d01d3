/* io_cxx.hpp - what the C++ shims of src/io share: io_gltf.cpp (the io
 * library) and the image plugins io_image_oiio.cpp / io_image_exr.cpp.
 * Header only: the plugin links no io library, so each shim compiles
 * its own copy. Not a public header; C callers never see it.
 *
 * WHAT IT DOES. one_line: a C++ library's message (tinygltf, OpenImageIO,
 * OpenEXR) as one line of an io_error. guard: the one exception boundary
 * of a shim's entry point: nothing thrown crosses into C; every exception
 * becomes an io_result that names the file (io.h CONVENTIONS).
 * channel_map: which of an image file's channels fills each channel the
 * caller asked for (both image plugins).
 * WHAT IT DOES NOT. Free what the call made (the caller does, on a
 * non-OK result), or catch anything outside the callable it is given.
 * USAGE.
 *   io_result r = io_cxx::guard(path, err, IO_ERR_FORMAT, "unknown error",
 *                               [&] { return load(path, out, err); });
 */
#ifndef EGOFUSE_IO_CXX_HPP
#define EGOFUSE_IO_CXX_HPP

#include <exception>
#include <new>
#include <string>

extern "C" {
#include "io.h"
}

namespace io_cxx {

/* Trailing newlines cut, inner ones made spaces; `fallback` when nothing
 * is left. */
inline std::string one_line(std::string s, const char *fallback)
{
    while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
    for (char &c : s)
        if (c == '\n' || c == '\r') c = ' ';
    return s.empty() ? std::string(fallback) : s;
}

/* f() (returning an io_result) with its exceptions turned into results:
 * bad_alloc "PATH: out of memory" (IO_ERR_NOMEM); another exception
 * "PATH: what" with code `fail`, its text as one line (fallback when
 * empty) when `fallback` is not NULL, else as it is; anything else
 * "PATH: unexpected exception". */
template <class F>
io_result guard(const char *path, io_error *err, io_result fail, const char *fallback, F &&f)
{
    try {
        return f();
    } catch (const std::bad_alloc &) {
        return io_fail(err, IO_ERR_NOMEM, "%s: out of memory", path);
    } catch (const std::exception &e) {
        if (fallback) return io_fail(err, fail, "%s: %s", path, one_line(e.what(), fallback).c_str());
        return io_fail(err, fail, "%s: %s", path, e.what());
    } catch (...) {
        return io_fail(err, fail, "%s: unexpected exception", path);
    }
}

/* The file channel of each of the `want` (1..4) channels asked for, from
 * a file of fc channels whose alpha is channel `alpha` (-1: none): its
 * colour channels (up to 3; one alone is repeated as grey, missing ones
 * are 0; an alpha-only file is read as grey), then its alpha when want
 * is 2 or 4. src[c]: a file channel, -1 = opaque (no alpha in the file),
 * -2 = 0. */
inline void channel_map(int fc, int alpha, int want, int src[4])
{
    int col[3], ncol = 0;
    for (int c = 0; c < fc && ncol < 3; c++)
        if (c != alpha) col[ncol++] = c;
    if (ncol == 0) col[ncol++] = 0;
    const bool out_alpha = want == 2 || want == 4;
    const int out_col = out_alpha ? want - 1 : want;
    for (int c = 0; c < out_col; c++) src[c] = ncol == 1 ? col[0] : (c < ncol ? col[c] : -2);
    if (out_alpha) src[want - 1] = alpha;
}

}  // namespace io_cxx

#endif
