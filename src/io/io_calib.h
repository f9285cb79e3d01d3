/* io_calib.h - camera calibration files as OpenCV writes them
 * (cv::FileStorage, YAML or XML) into a kin_lens (src/kin/kin_lens.h).
 *
 * WHAT IT READS (docs/lens.md has the format and an example)
 *   YAML ("%YAML:1.0" first, as FileStorage writes it; the header may be
 *   missing, as in ROS camera_info files) and XML (<opencv_storage>), told
 *   apart by the first character ('<' is XML). Of the file's top-level
 *   keys (matched ignoring case, so the old sample's Camera_Matrix works):
 *     camera_matrix | K | cameraMatrix | M       3x3 opencv-matrix
 *     distortion_coefficients | D | distCoeffs    1xN or Nx1, N = 4, 5, 8, 12
 *                                                 (14 when tauX = tauY = 0)
 *     image_width, image_height                   the size they are for
 *     fisheye_model (0/1), distortion_model       which lens model
 *   or, in a stereo file (cv::stereoCalibrate's sample: M1 D1 M2 D2, or
 *   K1 D1 K2 D2), the pair of the camera asked for. Matrices are
 *   "!!opencv-matrix" maps (YAML) or type_id="opencv-matrix" elements
 *   (XML) with rows, cols, dt (d or f) and data; a map with rows, cols and
 *   data without the tag (ROS) and, for the distortion, a plain sequence
 *   of numbers are read too. Every other key is skipped.
 *
 * WHICH MODEL
 *   fisheye_model: 1 (OpenCV's calibration sample) or a distortion_model
 *   naming "fisheye" / "equidistant" / "kannala_brandt" -> KIN_LENS_FISHEYE;
 *   fisheye_model: 0 or distortion_model "plumb_bob", "rational_polynomial",
 *   "radtan" -> KIN_LENS_BROWN. Without either: the keys K and D with
 *   exactly 4 coefficients (what cv::fisheye::calibrate users write) are a
 *   fisheye; everything else is Brown-Conrady. A Brown lens whose
 *   coefficients are all zero is still KIN_LENS_BROWN (kin_lens_distorts()
 *   says 0).
 *
 * ERRORS
 *   io_result + io_error: "FILE:LINE: KEY: reason" (a missing key names
 *   the keys looked for), IO_ERR_FORMAT for syntax, IO_ERR_MISSING,
 *   IO_ERR_VALUE for numbers (not finite, fx <= 0, a camera matrix whose
 *   last row is not 0 0 1, a lens that folds at its centre: kin_lens_check).
 *   The lens is written only on success. No allocation survives the call.
 */
#ifndef EGOFUSE_IO_CALIB_H
#define EGOFUSE_IO_CALIB_H

#include "io.h"
#include "../kin/kin_lens.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Reads path. camera: 0 for the first (or only) camera, 1 for the second
 * of a stereo file (M2/D2); a single-camera file serves both. */
io_result io_calib_load(const char *path, int camera, kin_lens *out, io_error *err);

/* The same from memory (name is used in the messages). */
io_result io_calib_parse(const char *name, const char *text, size_t len, int camera,
                         kin_lens *out, io_error *err);

#ifdef __cplusplus
}
#endif

#endif
