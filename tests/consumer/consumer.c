/* Uses only the installed headers and library: one query, checked against the closed form. */
#include <math.h>
#include <stdio.h>
#include <sdfccd/sdfccd.h>

int main(void)
{
    if (sdfccd_version() != SDFCCD_VERSION_ID) { fprintf(stderr, "header/library version mismatch\n"); return 1; }
    sdfccd_SdfId ground;
    if (sdfccd_create_half_space((sdfccd_Vec3){ 0, 0, 1 }, 0.0, &ground) != SDFCCD_OK) return 1;
    sdfccd_Vec3 tri[3] = { { 0, 0, 0.1 }, { 0.1, 0, 0.2 }, { 0, 0.1, 0.2 } };
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.linear_velocity.z = -10.0;
    sdfccd_QueryParams p = sdfccd_default_query_params();
    sdfccd_QueryResult r;
    if (sdfccd_query_triangle(ground, NULL, tri, &m, 0.0, 1.0 / 60.0, &p, NULL, 0, &r) != SDFCCD_OK) return 1;
    sdfccd_destroy_sdf(ground);
    printf("consumer: toi %.9f (expected 0.010000000)\n", r.toi);
    return r.hit && fabs(r.toi - 0.01) < 1e-6 && sdfccd_byte_count() == 0 ? 0 : 1;
}
