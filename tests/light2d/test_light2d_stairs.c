/* 2D shadows next to stair-stepped pixel-art caster edges (issue 28: dark
 * streaks radiated from the stairs' corners across lit ground). Casters
 * made here - a pixel-art diamond (45 degree stairs of 1 pixel), blocks
 * whose top is a 2:1 and a 3:1 staircase, and a diamond of 4-pixel art
 * pixels - are lit by hard and soft point lights from around them, and
 * every pixel that is not a caster is judged by marching segments through
 * the caster mask cell by cell (exact, independent of the library):
 *
 * - fully lit: the segments from the light to the pixel centre and to the
 *   centre turned by half a ray of the polar map each way (4/n radians, n
 *   = lx_light2d_rays: a ray of pseudo-angle width 8/n spans at most 8/n
 *   radians) cross no caster, and for a soft light neither do those from
 *   the pixel to the edges of the light's disk. There the light must be
 *   the unshadowed closed form, colour x (1 - (d/R)^2)^2, and no pixel
 *   may fall below 90% of it (a streak);
 * - fully shadowed: all three segments from the light cross a caster (and
 *   for a soft light those to the disk's edges too): the light must be 0.
 *
 * Caster pixels lit on their face (hard lights) are checked the same way:
 * the end of a segment from the light is in its first caster run when it
 * and every cell the segment visits after its first caster cell are
 * casters, past it when a free cell came between; where all the segments
 * (nine over the same angles) are in the first run the pixel must have
 * the closed form, where all are past it, 0. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "luxel/light2d.h"

#define W 256
#define H 256

/* Bound on |light - closed form| where a pixel is fully lit: float
 * rounding of the falloff (d from a float square root, then squares);
 * 1.4e-7 measured. */
#define LIT_TOL 4e-7
/* Bound on a soft light where a pixel sees none of its disk, as a share
 * of the unshadowed light: the penumbra model's filter (one occluder
 * distance per window, docs/light2d.md) leaves up to 0.044 of it measured
 * there; hard lights leave exactly 0. */
#define SOFT_DARK_TOL 0.1
/* Caster pixels judged wrong on their face, at most: lines that clip a
 * stair's corner and leave the caster through a gap narrower than the
 * judging lines' spacing (10 measured of about 130,000). */
#define FACE_WRONG_MAX 40

typedef struct scene {
    const char *name;
    uint8_t mask[W * H];
} scene;

static bool cast(const scene *s, int x, int y)
{
    return x >= 0 && y >= 0 && x < W && y < H && s->mask[y * W + x];
}

/* The caster pixels of the scenes, pixel (x, y) by its centre. */
static void make_scene(scene *s, int kind)
{
    memset(s->mask, 0, sizeof s->mask);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            bool c = false;
            if (kind == 0) /* 45 degree stairs of one pixel */
                c = fabs(x + 0.5 - 128.0) + fabs(y + 0.5 - 128.0) <= 40.0;
            else if (kind == 1 || kind == 2) { /* a block topped by k:1 stairs */
                int k = kind == 1 ? 2 : 3;
                c = x >= 48 && x < 208 && y < 190 && y >= 170 - (x - 48) / k;
            } else { /* a diamond of 4x4-pixel art pixels */
                int ax = x / 4, ay = y / 4;
                c = fabs(ax + 0.5 - 32.0) + fabs(ay + 0.5 - 32.0) <= 9.0;
            }
            s->mask[y * W + x] = c;
        }
    static const char *names[] = {"diamond 1:1", "stairs 2:1", "stairs 3:1", "art diamond"};
    s->name = names[kind];
}

/* The cells the segment (x0, y0) -> (x1, y1) visits, in order (a grid
 * walk: each step crosses the nearer cell boundary): whether any caster
 * cell before the end cell was visited, and through *run where the end
 * lies: 1 in the first caster run (a caster cell, and every cell since
 * the first caster cell a caster), -1 past it (a free cell came after a
 * caster cell), 0 before any caster. */
static bool segment_blocked(const scene *s, double x0, double y0, double x1, double y1, int *run)
{
    int cx = (int)floor(x0), cy = (int)floor(y0);
    int ex = (int)floor(x1), ey = (int)floor(y1);
    double dx = x1 - x0, dy = y1 - y0;
    int sx = dx > 0 ? 1 : -1, sy = dy > 0 ? 1 : -1;
    double tdx = dx != 0.0 ? fabs(1.0 / dx) : INFINITY, tdy = dy != 0.0 ? fabs(1.0 / dy) : INFINITY;
    double tx = dx != 0.0 ? ((dx > 0 ? cx + 1 - x0 : x0 - cx) * tdx) : INFINITY;
    double ty = dy != 0.0 ? ((dy > 0 ? cy + 1 - y0 : y0 - cy) * tdy) : INFINITY;
    bool blocked = false, in_run = false, left = false;
    for (int guard = 0; guard < 4 * (W + H); guard++) {
        bool c = cast(s, cx, cy);
        if (cx == ex && cy == ey) {
            *run = left || (in_run && !c) ? -1 : (c ? 1 : 0);
            return blocked;
        }
        if (c) {
            blocked = true;
            in_run = true;
        } else if (in_run)
            left = true;
        if (tx < ty) {
            tx += tdx;
            cx += sx;
        } else {
            ty += tdy;
            cy += sy;
        }
        if (tx > 1.0 && ty > 1.0 && !(cx == ex && cy == ey)) {
            /* rounding walked past the end: take the end cell */
            cx = ex;
            cy = ey;
        }
    }
    fail_msg("the grid walk missed its end cell");
    return blocked;
}

typedef struct stats {
    int lit, shadowed, faces_lit, faces_dark; /* pixels judged */
    int streaks;                              /* lit pixels below 90% */
    int shadow_wrong, face_wrong;
    double lit_err, shadow_err;
} stats;

static void judge(const scene *s, const lx_light2d_light *l, int n, const float *lm, stats *st)
{
    double delta = 4.0 / n;
    int shown = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double px = x + 0.5, py = y + 0.5;
            double dx = px - l->x, dy = py - l->y, d = hypot(dx, dy);
            if (d > l->radius - 2.0 || d < 2.0 * l->softness + 2.0)
                continue;
            /* the centre and the centre turned by +-delta about the light:
             * the segments from the light, and for a soft light those from
             * each of the three points to the edges of its disk (and
             * between); fully lit when none crosses a caster, fully
             * shadowed when all do (judged only where the segments from
             * the light agree) */
            int blocked = 0, first_run = 0, segments = 0;
            double qx[3], qy[3];
            for (int k = -1; k <= 1; k++) {
                double c = cos(k * delta), sn = sin(k * delta);
                qx[k + 1] = l->x + dx * c - dy * sn;
                qy[k + 1] = l->y + dx * sn + dy * c;
                int run;
                blocked += segment_blocked(s, l->x, l->y, qx[k + 1], qy[k + 1], &run);
                first_run += run;
                segments++;
            }
            /* a caster pixel's run can end in a gap narrower than the
             * three lines' spacing (a line clipping a stair's corner):
             * six more lines between them */
            bool face = cast(s, x, y) && l->softness <= 0.0f;
            for (int k = -3; k <= 3 && face && abs(first_run) == 3; k++) {
                if (k == 0)
                    continue;
                double c = cos(k * delta / 4.0), sn = sin(k * delta / 4.0);
                int run;
                segment_blocked(s, l->x, l->y, l->x + dx * c - dy * sn, l->y + dx * sn + dy * c,
                                &run);
                if (run != first_run / 3)
                    first_run = 0;
            }
            if (l->softness > 0.0f && (blocked == 0 || blocked == 3)) {
                for (int k = 0; k < 3 && (blocked == 0 || blocked == segments); k++)
                    for (int j = -1; j <= 1; j += 2) {
                        double e = l->softness * j;
                        int run;
                        blocked += segment_blocked(s, l->x - e * dy / d, l->y + e * dx / d, qx[k],
                                                   qy[k], &run);
                        segments++;
                    }
            }
            double q = 1.0 - (d * d) / ((double)l->radius * l->radius);
            double expect = q * q;
            float v = lm[3 * ((size_t)y * W + x)];
            if (cast(s, x, y)) {
                /* a caster lit on its face, where the three agree */
                if (l->softness > 0.0f)
                    continue;
                bool wrong = false;
                if (first_run == 3) {
                    st->faces_lit++;
                    wrong = fabs(v - expect) > LIT_TOL;
                } else if (first_run == -3) {
                    st->faces_dark++;
                    wrong = v != 0.0f;
                }
                if (wrong && st->face_wrong++ < 3 && getenv("L2_SHOW"))
                    print_message("  %s, light (%.1f, %.1f): face (%d, %d) %s but %.3f\n", s->name,
                                  l->x, l->y, x, y, first_run > 0 ? "lit" : "dark", v);
                continue;
            }
            if (blocked == 0) {
                st->lit++;
                double err = fabs(v - expect);
                if (err > st->lit_err)
                    st->lit_err = err;
                if (v < 0.9 * expect) {
                    st->streaks++;
                    if (shown++ < 4)
                        print_message("  %s, light (%.1f, %.1f) soft %g: pixel (%d, %d) lit "
                                      "%.3f of %.3f\n",
                                      s->name, l->x, l->y, l->softness, x, y, v, expect);
                }
            } else if (blocked == segments) {
                st->shadowed++;
                if (v / expect > st->shadow_err)
                    st->shadow_err = v / expect;
                if (v != 0.0f) {
                    st->shadow_wrong++;
                    if (v > 0.05f && getenv("L2_SHOW"))
                        print_message("  %s, light (%.1f, %.1f) soft %g: pixel (%d, %d) shadowed "
                                      "%.3f\n",
                                      s->name, l->x, l->y, l->softness, x, y, v);
                }
            }
        }
}

static void test_stairs(void **state)
{
    (void)state;
    static scene s;
    static const float pos[][2] = {{40.3f, 40.7f},  {128.2f, 20.4f},  {230.6f, 60.2f},
                                   {20.5f, 200.3f}, {236.4f, 150.6f}, {60.25f, 128.75f}};
    const int npos = (int)(sizeof pos / sizeof pos[0]);
    stats total[2];
    memset(total, 0, sizeof total);
    for (int kind = 0; kind < 4; kind++) {
        make_scene(&s, kind);
        lx_image img;
        assert_int_equal(lx_image_alloc(&img, W, H, 4), LX_OK);
        for (int i = 0; i < W * H; i++)
            img.data[4 * i + 3] = s.mask[i] ? 1.0f : 0.0f;
        lx_light2d *ctx = NULL;
        assert_int_equal(lx_light2d_create(&img, &(lx_light2d_desc){.threads = 2}, &ctx), LX_OK);
        float *lm = malloc((size_t)W * H * 3 * sizeof *lm);
        assert_non_null(lm);
        for (int p = 0; p < npos; p++)
            for (int soft = 0; soft < 2; soft++) {
                lx_light2d_light l = lx_light2d_light_defaults(LX_LIGHT2D_POINT);
                l.x = pos[p][0];
                l.y = pos[p][1];
                l.radius = 300.0f;
                l.softness = soft ? 3.0f : 0.0f;
                /* the light and its disk clear of casters */
                bool clear = true;
                for (int y = (int)(l.y - 6.0f); y <= (int)(l.y + 6.0f); y++)
                    for (int x = (int)(l.x - 6.0f); x <= (int)(l.x + 6.0f); x++)
                        clear &= !cast(&s, x, y);
                if (!clear)
                    continue;
                assert_int_equal(lx_light2d_set_lights(ctx, &l, 1), LX_OK);
                assert_int_equal(lx_light2d_render(ctx, lx_v3(0, 0, 0), NULL, NULL, lm), LX_OK);
                stats st;
                memset(&st, 0, sizeof st);
                judge(&s, &l, lx_light2d_rays(ctx, &l), lm, &st);
                stats *t = &total[soft];
                t->lit += st.lit;
                t->shadowed += st.shadowed;
                t->faces_lit += st.faces_lit;
                t->faces_dark += st.faces_dark;
                t->streaks += st.streaks;
                t->shadow_wrong += st.shadow_wrong;
                t->face_wrong += st.face_wrong;
                t->lit_err = fmax(t->lit_err, st.lit_err);
                t->shadow_err = fmax(t->shadow_err, st.shadow_err);
            }
        free(lm);
        lx_light2d_destroy(ctx);
        lx_image_free(&img);
    }
    for (int soft = 0; soft < 2; soft++) {
        const stats *t = &total[soft];
        print_message("%s: fully lit %d px: %d streaks (< 90%%), largest error %.2e; fully "
                      "shadowed %d px: %d not dark (largest %.3f of it); faces %d lit, %d dark: %d "
                      "wrong\n",
                      soft ? "soft 3" : "hard", t->lit, t->streaks, t->lit_err, t->shadowed,
                      t->shadow_wrong, t->shadow_err, t->faces_lit, t->faces_dark, t->face_wrong);
    }
    for (int soft = 0; soft < 2; soft++) {
        const stats *t = &total[soft];
        assert_true(t->lit > 100000 && t->shadowed > 20000);
        assert_int_equal(t->streaks, 0);
        assert_true(t->lit_err <= LIT_TOL);
    }
    assert_int_equal(total[0].shadow_wrong, 0);
    assert_true(total[1].shadow_err <= SOFT_DARK_TOL);
    assert_true(total[0].faces_lit > 50000 && total[0].faces_dark > 1000);
    assert_true(total[0].face_wrong <= FACE_WRONG_MAX);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stairs),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
