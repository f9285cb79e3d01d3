/* test_io_track.c - io_track.c: recorded tracking files and calibration
 * files on disk (round trip, errors naming file and line), and the live
 * UDP stream over loopback: good packets accepted in order, malformed,
 * reordered and duplicate packets rejected without stopping, the last good
 * pose kept and reported. */
#include "support/testutil.h"
#include <cmocka.h>
#include "support/files.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../src/io/io.h"

static kin_track_sample sample_at(double t, float x)
{
    kin_track_sample s;
    memset(&s, 0, sizeof s);
    s.t = t;
    s.valid = KIN_TRACK_HAND_R | KIN_TRACK_GLOVE_R | KIN_TRACK_SHOULDER_R;
    s.head_rot = s.hand_rot[0] = kin_quat_identity();
    s.hand_rot[1] = kin_quat_normalize((kin_quat){ 0.1f, 0.2f, 0.3f, 0.9f });
    s.hand_pos[1] = kin_v3(x, 1.0f, -0.4f);
    s.shoulder[1] = kin_v3(0.19f, 1.0f, 0.0f);
    for (int f = 0; f < 5; f++) s.glove[1][f] = 0.2f * (float)f;
    return s;
}

/* ------------------------------------------------------------ validity */

static void validity_file_errors(void **state)
{
    (void)state;
    char path[512];
    tu_tmp_path("bad_track.txt", path, sizeof path);
    tu_write_text(path, "egofuse-track 1\nt 0 SL 0 1 0\nt 0.1 SL 0 1\n");
    kin_track_sample *s = NULL;
    int n = -1;
    io_error err;
    assert_int_equal(io_track_load(path, &s, &n, &err), IO_ERR_FORMAT);
    assert_null(s);
    char want[600];
    snprintf(want, sizeof want, "%s:3: SL needs 3 numbers, got 2", path);
    assert_string_equal(err.msg, want);

    tu_tmp_path("does_not_exist.txt", path, sizeof path);
    assert_int_equal(io_track_load(path, &s, &n, &err), IO_ERR_NOT_FOUND);

    tu_tmp_path("bad_calib.txt", path, sizeof path);
    tu_write_text(path, "egofuse-calib 1\narm_scale 1 1\nhand_scale 1 1\nshoulder_scale 7\n");
    kin_user_calib c;
    assert_int_equal(io_user_calib_load(path, &c, &err), IO_ERR_FORMAT);
    snprintf(want, sizeof want, "%s:4:", path);
    assert_non_null(strstr(err.msg, want));

    /* an unstorable calibration is refused, not written */
    kin_user_calib bad = kin_user_calib_identity();
    bad.arm_scale[0] = 9.0f;
    tu_tmp_path("calib_refused.txt", path, sizeof path);
    assert_int_equal(io_user_calib_save(path, &bad, &err), IO_ERR_VALUE);
    assert_false(tu_exists(path));
}

static void validity_udp_bad_packets_keep_last_good(void **state)
{
    (void)state;
    io_track_udp rx, tx;
    io_error err;
    assert_int_equal(io_track_udp_listen(&rx, NULL, 0, &err), IO_OK);
    assert_true(rx.port > 0);
    assert_int_equal(io_track_udp_connect(&tx, "127.0.0.1", rx.port, &err), IO_OK);

    kin_track_sample out;
    int fresh = -1;
    /* nothing yet: an empty pose, no error */
    assert_int_equal(io_track_udp_poll(&rx, 0, &out, &fresh, &err), IO_OK);
    assert_int_equal(fresh, 0);
    assert_int_equal(out.valid, 0);

    kin_track_sample a = sample_at(1.25, 0.3f);
    assert_int_equal(io_track_udp_send(&tx, &a, 10, &err), IO_OK);
    uint8_t pk[KIN_TRACK_PACKET_SIZE];
    kin_track_sample b = sample_at(1.5, 0.5f);
    kin_track_packet_write(&b, 11, pk);
    pk[30] ^= 0x10;                                    /* corrupt: CRC */
    assert_int_equal(io_track_udp_send_raw(&tx, pk, sizeof pk, &err), IO_OK);
    assert_int_equal(io_track_udp_send_raw(&tx, "hello", 5, &err), IO_OK);  /* size */
    kin_track_sample c = sample_at(1.6, 0.6f);
    c.glove[1][0] = NAN;                               /* valid CRC, NaN inside */
    kin_track_packet_write(&c, 12, pk);
    assert_int_equal(io_track_udp_send_raw(&tx, pk, sizeof pk, &err), IO_OK);
    kin_track_sample d = sample_at(0.9, 0.9f);
    assert_int_equal(io_track_udp_send(&tx, &d, 9, &err), IO_OK);        /* stale */
    assert_int_equal(io_track_udp_send(&tx, &a, 10, &err), IO_OK);        /* duplicate */

    assert_int_equal(io_track_udp_poll(&rx, 1000, &out, &fresh, &err), IO_OK);
    assert_int_equal(fresh, 1);
    assert_int_equal(rx.packets, 6);
    assert_int_equal(rx.accepted, 1);
    assert_int_equal(rx.rejected, 3);
    assert_int_equal(rx.stale, 2);
    assert_true(out.t == 1.25);
    assert_true(out.hand_pos[1].x == 0.3f);
    assert_int_equal(rx.last_seq, 10);

    /* the report of a rejected packet names it and the pose kept */
    kin_track_packet_write(&b, 13, pk);
    assert_int_equal(io_track_udp_send_raw(&tx, pk, 100, &err), IO_OK);
    assert_int_equal(io_track_udp_poll(&rx, 1000, &out, &fresh, &err), IO_OK);
    assert_int_equal(fresh, 0);
    assert_string_equal(rx.status, "packet 7: size 100, expected 172 bytes; keeping the pose "
                                   "of seq 10 (t = 1.250 s)");
    assert_true(out.t == 1.25);
    io_track_udp_close(&tx);
    io_track_udp_close(&rx);
    assert_int_equal(rx.fd, -1);
}

static void validity_udp_arguments(void **state)
{
    (void)state;
    io_track_udp u;
    io_error err;
    /* any address of the user's choice: every interface, a host name */
    assert_int_equal(io_track_udp_listen(&u, "0.0.0.0", 0, &err), IO_OK);
    assert_true(u.port > 0);
    io_track_udp_close(&u);
    assert_int_equal(io_track_udp_listen(&u, "localhost", 0, &err), IO_OK);
    io_track_udp_close(&u);
    assert_int_equal(io_track_udp_listen(&u, "no-such-host.invalid", 0, &err), IO_ERR_ARGS);
    assert_non_null(strstr(err.msg, "'no-such-host.invalid' is neither a dotted IPv4 address "
                                    "nor a known host name"));
    /* an address of another machine cannot be bound: named */
    assert_int_equal(io_track_udp_listen(&u, "192.0.2.1", 0, &err), IO_ERR_DEVICE);
    assert_non_null(strstr(err.msg, "udp bind 192.0.2.1:0: "));
    assert_int_equal(io_track_udp_listen(&u, NULL, 70000, &err), IO_ERR_ARGS);
    assert_int_equal(io_track_udp_connect(&u, NULL, 0, &err), IO_ERR_ARGS);
}

/* -------------------------------------------------------------- results */

static void result_file_round_trip(void **state)
{
    (void)state;
    enum { N = 50 };
    kin_track_sample in[N];
    for (int i = 0; i < N; i++) in[i] = sample_at(0.01 * i, 0.01f * (float)i);
    in[7].valid = 0;
    char path[512];
    tu_tmp_path("track_rt.txt", path, sizeof path);
    io_error err;
    assert_int_equal(io_track_save(path, in, N, &err), IO_OK);
    kin_track_sample *out = NULL;
    int n = 0;
    if (io_track_load(path, &out, &n, &err) != IO_OK) fail_msg("%s", err.msg);
    assert_int_equal(n, N);
    for (int i = 0; i < N; i++) {
        assert_true(out[i].t == in[i].t);
        assert_int_equal(out[i].valid, in[i].valid);
        if (in[i].valid) {
            assert_memory_equal(&out[i].hand_pos[1], &in[i].hand_pos[1], sizeof(kin_vec3));
            assert_memory_equal(out[i].glove[1], in[i].glove[1], sizeof in[i].glove[1]);
        }
    }
    io_track_free(out);
    /* not increasing: refused */
    in[3].t = in[2].t;
    assert_int_equal(io_track_save(path, in, N, &err), IO_ERR_VALUE);
    assert_non_null(strstr(err.msg, "sample 4"));
}

static void result_calib_round_trip(void **state)
{
    (void)state;
    kin_user_calib c = kin_user_calib_identity(), back;
    c.arm_scale[0] = 1.1f; c.arm_scale[1] = 1.125f;
    c.hand_scale[0] = 0.95f; c.hand_scale[1] = 0.97f;
    c.shoulder_scale = 1.05f;
    c.arm_length[0] = 0.616f; c.arm_length[1] = 0.63f;
    c.shoulder_width = 0.397f;
    c.has_glove[1] = 1;
    for (int i = 0; i < 5; i++) { c.glove[1].raw_open[i] = 100.0f + i; c.glove[1].raw_fist[i] = 900.0f - i; }
    char path[512];
    tu_tmp_path("calib_rt.txt", path, sizeof path);
    io_error err;
    assert_int_equal(io_user_calib_save(path, &c, &err), IO_OK);
    if (io_user_calib_load(path, &back, &err) != IO_OK) fail_msg("%s", err.msg);
    assert_memory_equal(&back, &c, sizeof c);
}

static void result_udp_stream_in_order_and_wrap(void **state)
{
    (void)state;
    io_track_udp rx, tx;
    io_error err;
    assert_int_equal(io_track_udp_listen(&rx, "127.0.0.1", 0, &err), IO_OK);
    assert_int_equal(io_track_udp_connect(&tx, NULL, rx.port, &err), IO_OK);
    /* sequence numbers across the 32-bit wrap: 0xFFFFFFFE, 0xFFFFFFFF, 0, 1 */
    uint32_t seq = 0xFFFFFFFEu;
    for (int i = 0; i < 4; i++, seq++) {
        kin_track_sample s = sample_at(2.0 + 0.01 * i, (float)i);
        assert_int_equal(io_track_udp_send(&tx, &s, seq, &err), IO_OK);
    }
    kin_track_sample out;
    int fresh = 0;
    assert_int_equal(io_track_udp_poll(&rx, 1000, &out, &fresh, &err), IO_OK);
    assert_int_equal(fresh, 4);
    assert_int_equal(rx.last_seq, 1);
    assert_true(out.hand_pos[1].x == 3.0f);
    assert_true(out.t == 2.03);
    assert_int_equal(rx.rejected + rx.stale, 0);
    io_track_udp_close(&tx);
    io_track_udp_close(&rx);
}

int main(void)
{
    int f = 0;
    TU_GROUP(f, "io_track validity",
             cmocka_unit_test(validity_file_errors),
             cmocka_unit_test(validity_udp_bad_packets_keep_last_good),
             cmocka_unit_test(validity_udp_arguments));
    TU_GROUP(f, "io_track results",
             cmocka_unit_test(result_file_round_trip),
             cmocka_unit_test(result_calib_round_trip),
             cmocka_unit_test(result_udp_stream_in_order_and_wrap));
    return f ? 1 : 0;
}
