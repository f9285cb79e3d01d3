/* test_kin_track.c - tracking samples (kin_track.c): the recorded text
 * format (strict errors with line numbers, exact round trip), the UDP
 * packet (byte layout, CRC, rejection of corrupt or invalid packets) and
 * the body frame, against hand-worked answers. */
#include "support/testutil.h"
#include "support/tu_kin.h"
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../src/kin/kin.h"

/* Parses text; returns the result and fills line / why. */
static int parse(const char *text, kin_track_sample *out, int cap, int *count, int *line,
                 char *why)
{
    return kin_track_parse(text, strlen(text), out, cap, count, line, why, 256);
}

static void expect_error(const char *text, int want_line, const char *want_in_why)
{
    kin_track_sample s[8];
    int count = -1, line = -1;
    char why[256] = "";
    int r = parse(text, s, 8, &count, &line, why);
    if (r != -1) fail_msg("accepted: %s", text);
    if (line != want_line) fail_msg("line %d, expected %d (%s)", line, want_line, why);
    if (!strstr(why, want_in_why)) fail_msg("reason '%s' lacks '%s'", why, want_in_why);
}

static kin_track_sample random_sample(tu_rng *g, double t)
{
    kin_track_sample s;
    memset(&s, 0, sizeof s);
    s.t = t;
    s.valid = (uint32_t)tu_int(g, KIN_TRACK_ALL + 1);
    s.head_pos = tu_v3b(g, -2, 2, 0, 2, -2, 2);
    s.head_rot = kin_quat_normalize(tu_quat(g, -1, 1));
    for (int k = 0; k < 2; k++) {
        s.shoulder[k] = tu_v3b(g, -1, 1, 0, 2, -1, 1);
        s.hand_pos[k] = tu_v3b(g, -1, 1, 0, 2, -1, 1);
        s.hand_rot[k] = kin_quat_normalize(tu_quat(g, -1, 1));
        for (int f = 0; f < 5; f++) s.glove[k][f] = tu_unit(g);
    }
    return s;
}

/* Equal in every valid part, bit for bit. */
static void expect_same(const kin_track_sample *a, const kin_track_sample *b)
{
    assert_int_equal(a->valid, b->valid);
    assert_true(a->t == b->t);
    if (a->valid & KIN_TRACK_HEAD) {
        assert_memory_equal(&a->head_pos, &b->head_pos, sizeof a->head_pos);
        NEAR(a->head_rot.x, b->head_rot.x, 3e-7); NEAR(a->head_rot.y, b->head_rot.y, 3e-7);
        NEAR(a->head_rot.z, b->head_rot.z, 3e-7); NEAR(a->head_rot.w, b->head_rot.w, 3e-7);
    }
    for (int k = 0; k < 2; k++) {
        if (a->valid & (KIN_TRACK_SHOULDER_L << k))
            assert_memory_equal(&a->shoulder[k], &b->shoulder[k], sizeof(kin_vec3));
        if (a->valid & (KIN_TRACK_HAND_L << k)) {
            assert_memory_equal(&a->hand_pos[k], &b->hand_pos[k], sizeof(kin_vec3));
            NEAR(a->hand_rot[k].w, b->hand_rot[k].w, 3e-7);
            NEAR(a->hand_rot[k].x, b->hand_rot[k].x, 3e-7);
        }
        if (a->valid & (KIN_TRACK_GLOVE_L << k))
            assert_memory_equal(a->glove[k], b->glove[k], sizeof a->glove[k]);
    }
}

/* ------------------------------------------------------------ validity */

static void validity_file_errors_name_the_line(void **state)
{
    (void)state;
    expect_error("", 0, "header");
    expect_error("egofuse-track 2\n", 1, "first line");
    expect_error("egofuse-track 1\n# ok\nt 0 X 1 2 3\n", 3, "unknown tag 'X'");
    expect_error("egofuse-track 1\nt 0 SL 1 2 3 SL 1 2 3\n", 2, "twice");
    expect_error("egofuse-track 1\nt 0 SL 1 2\n", 2, "SL needs 3 numbers, got 2");
    expect_error("egofuse-track 1\nt 0 SL 1 2 SR 1 2 3\n", 2, "SL needs 3 numbers, got 2");
    expect_error("egofuse-track 1\n\nt 0 SL 1 nan 3\n", 3, "bad number 'nan'");
    expect_error("egofuse-track 1\nt 0 SL 1 inf 3\n", 2, "bad number 'inf'");
    expect_error("egofuse-track 1\nt 0 SL 1 0x10 3\n", 2, "bad number");
    expect_error("egofuse-track 1\nt 0 SL 1 2 3x\n", 2, "bad number '3x'");
    expect_error("egofuse-track 1\nt 0 SL 1 1e999 3\n", 2, "bad number");
    expect_error("egofuse-track 1\nt 0 GL 0 0.5 1 1.5 0\n", 2, "not in [0, 1]");
    expect_error("egofuse-track 1\nt 0 GR 0 0.5 1 -0.01 0\n", 2, "not in [0, 1]");
    expect_error("egofuse-track 1\nt 0 H 0 0 0 0 0 0 0.9\n", 2, "unit quaternion");
    expect_error("egofuse-track 1\nt 0 HL 0 0 0 0 0 0 1.01\n", 2, "unit quaternion");
    expect_error("egofuse-track 1\nt 1\nt 2\nt 2\n", 4, "does not increase");
    expect_error("egofuse-track 1\nt 1\nt 0.5\n", 3, "does not increase");
    expect_error("egofuse-track 1\n0 SL 1 2 3\n", 2, "starts with 't'");
    expect_error("egofuse-track 1\nt\n", 2, "needs a time stamp");
    expect_error("egofuse-track 1\nt 1 SL 1 2 3 4\n", 2, "unknown tag '4'");
    /* a line far too long */
    char big[3000];
    strcpy(big, "egofuse-track 1\nt 0");
    size_t n = strlen(big);
    while (n < sizeof big - 8) { memcpy(big + n, " SL", 3); n += 3; }
    big[n] = '\0';
    expect_error(big, 2, "longer than");
}

static void validity_capacity_and_count(void **state)
{
    (void)state;
    const char *text = "egofuse-track 1\nt 0\nt 1\nt 2\n";
    int count = -1, line = -1;
    char why[256];
    assert_int_equal(parse(text, NULL, 0, &count, &line, why), 0);
    assert_int_equal(count, 3);
    kin_track_sample s[2];
    assert_int_equal(parse(text, s, 2, &count, &line, why), -1);
    assert_int_equal(line, 4);
    assert_non_null(strstr(why, "capacity"));
}

static void validity_sample_validate(void **state)
{
    (void)state;
    kin_track_sample s;
    memset(&s, 0, sizeof s);
    s.head_rot = kin_quat_identity();
    s.hand_rot[0] = s.hand_rot[1] = kin_quat_identity();
    s.valid = KIN_TRACK_ALL;
    char why[128];
    assert_int_equal(kin_track_sample_validate(&s, why, sizeof why), 0);
    s.hand_pos[1].y = NAN;
    assert_int_equal(kin_track_sample_validate(&s, why, sizeof why), -1);
    assert_non_null(strstr(why, "right hand"));
    s.valid &= ~(uint32_t)KIN_TRACK_HAND_R; /* missing parts are not checked */
    assert_int_equal(kin_track_sample_validate(&s, why, sizeof why), 0);
    s.glove[0][2] = NAN;
    assert_int_equal(kin_track_sample_validate(&s, why, sizeof why), -1);
    assert_non_null(strstr(why, "left glove value 3"));
    s.glove[0][2] = 0.5f;
    s.valid |= 0x100;
    assert_int_equal(kin_track_sample_validate(&s, why, sizeof why), -1);
    s.valid = 0;
    s.t = INFINITY;
    assert_int_equal(kin_track_sample_validate(&s, why, sizeof why), -1);
}

static void validity_packet_rejects(void **state)
{
    (void)state;
    tu_rng g = { 0x7061636b };
    kin_track_sample s = random_sample(&g, 12.5), r;
    s.valid = KIN_TRACK_ALL;
    uint8_t pk[KIN_TRACK_PACKET_SIZE];
    uint32_t seq = 0;
    char why[128];
    kin_track_packet_write(&s, 7, pk);
    assert_int_equal(kin_track_packet_read(pk, sizeof pk, &r, &seq, why, sizeof why), 0);
    /* every single flipped bit is caught (CRC or magic/version check) */
    for (int i = 0; i < KIN_TRACK_PACKET_SIZE; i++) {
        uint8_t bad[KIN_TRACK_PACKET_SIZE];
        memcpy(bad, pk, sizeof pk);
        bad[i] ^= (uint8_t)(1u << (i % 8));
        if (kin_track_packet_read(bad, sizeof bad, &r, &seq, why, sizeof why) != -1)
            fail_msg("flipped bit in byte %d accepted", i);
    }
    assert_int_equal(kin_track_packet_read(pk, sizeof pk - 1, &r, &seq, why, sizeof why), -1);
    assert_non_null(strstr(why, "size 171"));
    /* a valid CRC around invalid contents: NaN, glove out of range, bad version */
    kin_track_sample b = s;
    b.hand_pos[0].x = NAN;
    kin_track_packet_write(&b, 8, pk);
    assert_int_equal(kin_track_packet_read(pk, sizeof pk, &r, &seq, why, sizeof why), -1);
    assert_non_null(strstr(why, "left hand"));
    b = s;
    b.glove[1][4] = 1.25f;
    kin_track_packet_write(&b, 9, pk);
    assert_int_equal(kin_track_packet_read(pk, sizeof pk, &r, &seq, why, sizeof why), -1);
    assert_non_null(strstr(why, "not in [0, 1]"));
    kin_track_packet_write(&s, 10, pk);
    pk[4] = 2; /* version 2, CRC fixed up */
    uint32_t crc = tu_crc32(0, pk, 168);
    for (int i = 0; i < 4; i++) pk[168 + i] = (uint8_t)(crc >> (8 * i));
    assert_int_equal(kin_track_packet_read(pk, sizeof pk, &r, &seq, why, sizeof why), -1);
    assert_non_null(strstr(why, "version 2"));
}

/* -------------------------------------------------------------- results */

static void result_parse_hand_written_file(void **state)
{
    (void)state;
    const char *text =
        "egofuse-track 1\r\n"
        "# recorded by hand\n"
        "\n"
        "t 0.5 H 0 1.25 -0.08 0 0 0 1 SL -0.19 1 0 SR 0.19 1 0\n"
        "  t 0.511 HR 0.2 1 -0.4 0 0.6 0 0.8 GR 0 .25 0.5 0.75 1 # trailing comment\r\n"
        "t 0.522\n";
    kin_track_sample s[4];
    int count = 0, line = -1;
    char why[256] = "";
    int r = parse(text, s, 4, &count, &line, why);
    if (r) fail_msg("%d: %s", line, why);
    assert_int_equal(count, 3);
    assert_true(s[0].t == 0.5);
    assert_int_equal(s[0].valid, KIN_TRACK_HEAD | KIN_TRACK_SHOULDER_L | KIN_TRACK_SHOULDER_R);
    assert_true(s[0].head_pos.y == 1.25f && s[0].head_pos.z == -0.08f);
    assert_true(s[0].head_rot.w == 1.0f);
    assert_true(s[0].shoulder[0].x == -0.19f && s[0].shoulder[1].x == 0.19f);
    assert_int_equal(s[1].valid, KIN_TRACK_HAND_R | KIN_TRACK_GLOVE_R);
    assert_true(s[1].hand_rot[1].y == 0.6f && s[1].hand_rot[1].w == 0.8f);
    assert_true(s[1].glove[1][1] == 0.25f && s[1].glove[1][4] == 1.0f);
    assert_int_equal(s[2].valid, 0);
    assert_true(s[2].t == 0.522);
}

static void result_format_parse_round_trip(void **state)
{
    (void)state;
    tu_rng g = { 0x74726163 };
    enum { N = 200 };
    static char text[N * 400 + 64];
    static kin_track_sample in[N], out[N];
    size_t len = 0;
    len += (size_t)snprintf(text, sizeof text, "%s", kin_track_header());
    double t = 100.0;
    for (int i = 0; i < N; i++) {
        t += 0.001 + 0.01 * tu_unit(&g);
        in[i] = random_sample(&g, t);
        int n = kin_track_format_line(&in[i], text + len, sizeof text - len);
        assert_true(n > 0 && (size_t)n < sizeof text - len);
        len += (size_t)n;
    }
    /* the size query */
    assert_int_equal(kin_track_format_line(&in[0], NULL, 0),
                     kin_track_format_line(&in[0], text + len, sizeof text - len));
    int count = 0, line = 0;
    char why[256] = "";
    int r = kin_track_parse(text, len, out, N, &count, &line, why, sizeof why);
    if (r) fail_msg("%d: %s", line, why);
    assert_int_equal(count, N);
    for (int i = 0; i < N; i++) expect_same(&in[i], &out[i]);
    /* A position next to the 1e30 limit: 1e30 as a double, 1e30f =
     * 1.00000002e30 as the float kept; the line written from it reads back
     * (the calibration file had this bug: docs/fuzzing.md). Above 1e30f as
     * a float: out of range. */
    const char *edge = "t 1 H 1000000000000000000084467440731 0 0 0 0 0 1";
    kin_track_sample e, e2;
    if (kin_track_parse_line(edge, strlen(edge), &e, why, sizeof why) != 1) fail_msg("%s", why);
    assert_true(e.head_pos.x == 1e30f);
    char l[400];
    int n = kin_track_format_line(&e, l, sizeof l);
    assert_true(n > 0 && n < (int)sizeof l);
    if (kin_track_parse_line(l, (size_t)n - 1, &e2, why, sizeof why) != 1) fail_msg("%s: %s", why, l);
    expect_same(&e, &e2);
    const char *over = "t 1 H 1.0000001e30 0 0 0 0 0 1";
    assert_int_equal(kin_track_parse_line(over, strlen(over), &e2, why, sizeof why), -1);
    assert_non_null(strstr(why, "out of range"));
}

static void result_packet_layout_and_round_trip(void **state)
{
    (void)state;
    kin_track_sample s;
    memset(&s, 0, sizeof s);
    s.t = 1.0;
    s.valid = KIN_TRACK_HEAD | KIN_TRACK_GLOVE_R;
    s.head_pos = kin_v3(1.0f, -2.0f, 0.5f);
    s.head_rot = kin_quat_identity();
    s.hand_rot[0] = s.hand_rot[1] = kin_quat_identity();
    s.glove[1][4] = 0.75f;
    uint8_t pk[KIN_TRACK_PACKET_SIZE];
    kin_track_packet_write(&s, 0x01020304u, pk);
    assert_memory_equal(pk, "EGTK", 4);
    const uint8_t ver_valid_seq[8] = { 1, 0, 0x41, 0, 4, 3, 2, 1 };
    assert_memory_equal(pk + 4, ver_valid_seq, 8);
    const uint8_t one[8] = { 0, 0, 0, 0, 0, 0, 0xF0, 0x3F }; /* 1.0 as f64 LE */
    assert_memory_equal(pk + 12, one, 8);
    const uint8_t f1[4] = { 0, 0, 0x80, 0x3F }, fm2[4] = { 0, 0, 0, 0xC0 };
    assert_memory_equal(pk + 20, f1, 4);          /* head x = 1.0f */
    assert_memory_equal(pk + 24, fm2, 4);         /* head y = -2.0f */
    const uint8_t f075[4] = { 0, 0, 0x40, 0x3F };
    assert_memory_equal(pk + 20 + 4 * 36, f075, 4); /* last float: right little */
    uint32_t crc = tu_crc32(0, pk, 168);
    assert_int_equal(pk[168] | pk[169] << 8 | pk[170] << 16 | (uint32_t)pk[171] << 24, crc);

    tu_rng g = { 0x1234 };
    for (int i = 0; i < 100; i++) {
        kin_track_sample a = random_sample(&g, tu_range(&g, 0, 1000)), b;
        uint32_t seq = 0;
        char why[128];
        kin_track_packet_write(&a, (uint32_t)i * 77u, pk);
        if (kin_track_packet_read(pk, sizeof pk, &b, &seq, why, sizeof why))
            fail_msg("packet %d: %s", i, why);
        assert_int_equal(seq, (uint32_t)i * 77u);
        expect_same(&a, &b);
    }
}

static void result_body_frame(void **state)
{
    (void)state;
    kin_quat q = kin_body_frame(kin_v3(-0.2f, 1, 0), kin_v3(0.2f, 1, 0), kin_v3(0, 1.3f, -0.05f));
    NEAR(fabs(q.w), 1.0, 1e-6);
    /* turned 90 degrees left (about +Y): right shoulder at -Z */
    q = kin_body_frame(kin_v3(0, 1, 0.2f), kin_v3(0, 1, -0.2f), kin_v3(0.3f, 1.4f, 0));
    kin_vec3 x = kin_quat_rotate(q, kin_v3(1, 0, 0)), y = kin_quat_rotate(q, kin_v3(0, 1, 0));
    NEAR(x.z, -1.0, 1e-6); NEAR(y.y, 1.0, 1e-6);
    /* shoulders tilted 30 degrees (roll): Y is world up without its X part */
    float c = cosf(0.5235988f), sn = sinf(0.5235988f);
    q = kin_body_frame(kin_v3(-0.2f * c, 1 - 0.2f * sn, 0), kin_v3(0.2f * c, 1 + 0.2f * sn, 0),
                       kin_v3(0, 1.3f, -0.08f));
    y = kin_quat_rotate(q, kin_v3(0, 1, 0));
    NEAR(y.x, -sn, 1e-6); NEAR(y.y, c, 1e-6); NEAR(y.z, 0.0, 1e-6);
    /* shoulder line vertical: towards the head */
    q = kin_body_frame(kin_v3(0, 0.8f, 0), kin_v3(0, 1.2f, 0), kin_v3(-0.3f, 1.0f, 0));
    y = kin_quat_rotate(q, kin_v3(0, 1, 0));
    NEAR(y.x, -1.0, 1e-6);
}

int main(void)
{
    int f = 0;
    TU_GROUP(f, "kin_track validity",
             cmocka_unit_test(validity_file_errors_name_the_line),
             cmocka_unit_test(validity_capacity_and_count),
             cmocka_unit_test(validity_sample_validate),
             cmocka_unit_test(validity_packet_rejects));
    TU_GROUP(f, "kin_track results",
             cmocka_unit_test(result_parse_hand_written_file),
             cmocka_unit_test(result_format_parse_round_trip),
             cmocka_unit_test(result_packet_layout_and_round_trip),
             cmocka_unit_test(result_body_frame));
    return f ? 1 : 0;
}
