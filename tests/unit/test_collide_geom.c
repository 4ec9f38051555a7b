/* test_collide_geom.c - the collision code's segment geometry (collide_int.h):
 * the normal a wall pushes a moving circle along. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <cmocka.h>

#include "collide_int.h"

/* colg_seg_normal: a unit vector (2.30) from the segment's point nearest p toward
 * p, wherever p is (beside the segment, or beyond an end, in any direction), and
 * the segment's front normal (its right going a -> b) when p is on it. Checked
 * against the nearest point found in doubles. */
static void test_seg_normal_points_at_p(void **state)
{
    (void)state;
    static const int64_t segs[][4] = {{0, 0, 4096, 0}, {0, 0, 0, 4096}, {100, -50, -3000, 2000}, {7, 7, 8, 7}};
    for (size_t k = 0; k < sizeof segs / sizeof segs[0]; k++) {
        grid_pt a = {segs[k][0], segs[k][1]}, b = {segs[k][2], segs[k][3]};
        double abx = (double)(b.x - a.x), aby = (double)(b.y - a.y), l2 = abx * abx + aby * aby;
        for (int64_t dy = -6000; dy <= 6000; dy += 250)
            for (int64_t dx = -6000; dx <= 6000; dx += 250) {
                grid_pt p = {a.x + dx, a.y + dy};
                int32_t nx, ny;
                assert_int_equal(colg_seg_normal(p, a, b, &nx, &ny), 1);
                double t = ((double)(p.x - a.x) * abx + (double)(p.y - a.y) * aby) / l2;
                t = t < 0 ? 0 : (t > 1 ? 1 : t);
                double vx = (double)p.x - ((double)a.x + t * abx), vy = (double)p.y - ((double)a.y + t * aby);
                double len = sqrt(vx * vx + vy * vy), ux = nx / 1073741824.0, uy = ny / 1073741824.0;
                assert_true(fabs(sqrt(ux * ux + uy * uy) - 1) < 1e-6);
                if (len > 1e-9) {
                    if (ux * vx / len + uy * vy / len < 1 - 1e-6)
                        fprintf(stderr, "seg %zu, p (%lld, %lld): normal (%f, %f)\n", k, (long long)p.x, (long long)p.y,
                                ux, uy);
                    assert_true(ux * vx / len + uy * vy / len > 1 - 1e-6);
                } else { /* on the segment: its front normal */
                    double fl = sqrt(l2);
                    assert_true(ux * aby / fl - uy * abx / fl > 1 - 1e-6);
                }
            }
        /* both ends themselves */
        int32_t nx, ny;
        colg_seg_normal(a, a, b, &nx, &ny);
        assert_true((double)nx * aby - (double)ny * abx > 0);
        colg_seg_normal(b, a, b, &nx, &ny);
        assert_true((double)nx * aby - (double)ny * abx > 0);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_seg_normal_points_at_p),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
