/* The test oracle: the per-texel lighting document's brute-force algorithm
 * (UvToWorld: every texel searches every triangle with barycentrics;
 * DynamicLight: every texel, every light, every triangle shadow test) and
 * the light model (Filament's physically based punctual lights, the
 * document's classic falloff, its blur shadow), written from their
 * formulas in double precision: nothing here calls src/light, src/bake or
 * src/trace. See reference.h. */
#include "reference.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- small double vector helpers ----------------------------------------- */

static void d_sub(const double a[3], const double b[3], double r[3])
{
    r[0] = a[0] - b[0], r[1] = a[1] - b[1], r[2] = a[2] - b[2];
}
double lx_ref_dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
void lx_ref_cross(const double a[3], const double b[3], double r[3])
{
    r[0] = a[1] * b[2] - a[2] * b[1];
    r[1] = a[2] * b[0] - a[0] * b[2];
    r[2] = a[0] * b[1] - a[1] * b[0];
}
void lx_ref_normalize(double a[3])
{
    double l = sqrt(lx_ref_dot(a, a));
    if (l > 0)
        a[0] /= l, a[1] /= l, a[2] /= l;
}

/* world = M * (p, 1), column-major M (m[col*4 + row]) */
static void d_point(const lx_mat4 *m, const double p[3], double r[3])
{
    for (int row = 0; row < 3; row++)
        r[row] = (double)m->m[0 * 4 + row] * p[0] + (double)m->m[1 * 4 + row] * p[1] +
                 (double)m->m[2 * 4 + row] * p[2] + (double)m->m[3 * 4 + row];
}

/* Normal matrix: inverse transpose of M's upper 3x3, from the adjugate.
 * n_world = cof(A) n / det(A); the 1/det keeps the orientation of
 * mirrored transforms consistent with transforming the normal. */
static void d_normal_matrix(const lx_mat4 *m, double nm[3][3])
{
    double a[3][3]; /* a[row][col] */
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            a[r][c] = m->m[c * 4 + r];
    double cof[3][3];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            int r1 = (r + 1) % 3, r2 = (r + 2) % 3, c1 = (c + 1) % 3, c2 = (c + 2) % 3;
            cof[r][c] = a[r1][c1] * a[r2][c2] - a[r1][c2] * a[r2][c1];
        }
    double det = a[0][0] * cof[0][0] + a[0][1] * cof[0][1] + a[0][2] * cof[0][2];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            nm[r][c] = cof[r][c] / det; /* (A^-1)^T = cof(A) / det */
}

static void d_apply3(double m[3][3], const double v[3], double r[3])
{
    for (int i = 0; i < 3; i++)
        r[i] = m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2];
}

static void from_vec(lx_vec3 v, double r[3])
{
    r[0] = v.x, r[1] = v.y, r[2] = v.z;
}
static lx_vec3 to_vec(const double r[3])
{
    return lx_v3((float)r[0], (float)r[1], (float)r[2]);
}

/* ---- scene in world space ---------------------------------------------------- */

void lx_ref_scene_build(const lx_scene *scene, lx_ref_scene *out)
{
    memset(out, 0, sizeof *out);
    uint32_t n = 0;
    for (uint32_t i = 0; i < scene->node_count; i++)
        for (uint32_t k = 0; k < scene->nodes[i].mesh_count; k++)
            n += scene->meshes[scene->nodes[i].meshes[k]].triangle_count;
    out->tris = calloc(n ? n : 1, sizeof *out->tris);
    for (int c = 0; c < 3; c++)
        out->lo[c] = INFINITY, out->hi[c] = -INFINITY;
    for (uint32_t i = 0; i < scene->node_count; i++) {
        const lx_node *node = &scene->nodes[i];
        for (uint32_t k = 0; k < node->mesh_count; k++) {
            const lx_mesh *m = &scene->meshes[node->meshes[k]];
            for (uint32_t t = 0; t < m->triangle_count; t++) {
                lx_ref_triangle *tri = &out->tris[out->count++];
                tri->node = i;
                tri->mesh = node->meshes[k];
                tri->triangle = t;
                for (int v = 0; v < 3; v++) {
                    double p[3];
                    from_vec(m->positions[m->indices[3 * t + v]], p);
                    d_point(&node->world, p, tri->p[v]);
                    for (int c = 0; c < 3; c++) {
                        out->lo[c] = fmin(out->lo[c], tri->p[v][c]);
                        out->hi[c] = fmax(out->hi[c], tri->p[v][c]);
                    }
                }
            }
        }
    }
    if (out->count) {
        double d[3];
        d_sub(out->hi, out->lo, d);
        out->diagonal = (float)sqrt(lx_ref_dot(d, d));
    }
    if (!(out->diagonal > 0.0f))
        out->diagonal = 1.0f;
}

void lx_ref_scene_free(lx_ref_scene *rs)
{
    free(rs->tris);
    memset(rs, 0, sizeof *rs);
}

/* ---- rays ----------------------------------------------------------------- */

bool lx_ref_intersect(const lx_ref_triangle *tri, const double o[3], const double d[3], double tmin,
                      double tmax, double *t, double *u, double *v, double *margin)
{
    /* Moller & Trumbore, "Fast, minimum storage ray-triangle intersection" */
    double e1[3], e2[3], pv[3], tv[3], qv[3];
    d_sub(tri->p[1], tri->p[0], e1);
    d_sub(tri->p[2], tri->p[0], e2);
    lx_ref_cross(d, e2, pv);
    double det = lx_ref_dot(e1, pv);
    if (margin)
        *margin = -INFINITY;
    *t = *u = *v = NAN;
    if (det == 0.0)
        return false;
    double inv = 1.0 / det;
    d_sub(o, tri->p[0], tv);
    double uu = lx_ref_dot(tv, pv) * inv;
    lx_ref_cross(tv, e1, qv);
    double vv = lx_ref_dot(d, qv) * inv;
    double tt = lx_ref_dot(e2, qv) * inv;
    *t = tt, *u = uu, *v = vv;
    double m = fmin(fmin(uu, vv), 1.0 - uu - vv);
    if (margin)
        *margin = m;
    return m >= 0.0 && tt >= tmin && tt <= tmax;
}

/* Distances along a ray closer than this (relative, at least 1e-6 absolute)
 * are within float rounding of each other. */
static double t_slack(double tmax)
{
    return 1e-6 * (isfinite(tmax) && fabs(tmax) > 1.0 ? fabs(tmax) : 1.0);
}

/* Does this plane crossing make the answer depend on rounding? */
static bool near_tie(double t, double margin, double tmin, double tmax, double eps)
{
    double s = t_slack(tmax);
    if (!isfinite(margin) || !(t >= tmin - s && t <= tmax + s))
        return false;
    if (fabs(margin) < eps)
        return true; /* passes next to an edge */
    if (margin >= 0 && (fabs(t - tmin) <= s || fabs(t - tmax) <= s))
        return true; /* hits right at an end of the range */
    return false;
}

bool lx_ref_closest(const lx_ref_scene *rs, lx_vec3 origin, lx_vec3 dir, double tmin, double tmax,
                    double edge_eps, lx_ref_hit *hit, bool *ambiguous)
{
    double o[3], d[3];
    from_vec(origin, o);
    from_vec(dir, d);
    bool found = false, amb = false;
    lx_ref_hit best = {0};
    best.t = INFINITY;
    double second = INFINITY;
    for (uint32_t i = 0; i < rs->count; i++) {
        double t, u, v, margin;
        bool h = lx_ref_intersect(&rs->tris[i], o, d, tmin, tmax, &t, &u, &v, &margin);
        if (near_tie(t, margin, tmin, tmax, edge_eps))
            amb = true;
        if (!h)
            continue;
        if (t < best.t) {
            second = best.t;
            best = (lx_ref_hit){t, u, v, rs->tris[i].node, rs->tris[i].mesh, rs->tris[i].triangle};
            found = true;
        } else if (t < second) {
            second = t;
        }
    }
    if (found && isfinite(second) && second - best.t <= t_slack(best.t))
        amb = true;
    if (hit)
        *hit = best;
    if (ambiguous)
        *ambiguous = amb;
    return found;
}

bool lx_ref_occluded(const lx_ref_scene *rs, lx_vec3 origin, lx_vec3 dir, double tmin, double tmax,
                     double edge_eps, bool *ambiguous)
{
    double o[3], d[3];
    from_vec(origin, o);
    from_vec(dir, d);
    bool blocked = false, amb = false;
    for (uint32_t i = 0; i < rs->count; i++) {
        double t, u, v, margin;
        if (lx_ref_intersect(&rs->tris[i], o, d, tmin, tmax, &t, &u, &v, &margin))
            blocked = true;
        if (near_tie(t, margin, tmin, tmax, edge_eps))
            amb = true;
    }
    if (ambiguous)
        *ambiguous = amb;
    return blocked;
}

/* ---- texel map ---------------------------------------------------------- */

int lx_ref_uv_set(const lx_mesh *mesh)
{
    if (mesh->uv[1])
        return 1;
    return mesh->uv[0] ? 0 : -1;
}

bool lx_ref_uv_barycentric(lx_vec2 a, lx_vec2 b, lx_vec2 c, double px, double py, double w[3])
{
    /* the document's UvToWorld: P - P1 = v (P2 - P1) + w (P3 - P1), Cramer's rule */
    double ax = a.x, ay = a.y, bx = b.x, by = b.y, cx = c.x, cy = c.y;
    double denom = (bx - ax) * (cy - ay) - (cx - ax) * (by - ay);
    if (denom == 0.0)
        return false;
    double v = ((px - ax) * (cy - ay) - (cx - ax) * (py - ay)) / denom;
    double ww = ((bx - ax) * (py - ay) - (px - ax) * (by - ay)) / denom;
    w[0] = 1.0 - v - ww;
    w[1] = v;
    w[2] = ww;
    return true;
}

void lx_ref_texel_map(const lx_scene *scene, uint32_t node_index, int width, int height,
                      lx_ref_map *out)
{
    const lx_node *node = &scene->nodes[node_index];
    out->node = node_index;
    out->width = width;
    out->height = height;
    out->texels = calloc((size_t)width * height, sizeof *out->texels);
    double nm[3][3];
    d_normal_matrix(&node->world, nm);
    for (int y = 0; y < height; y++)
        for (int x = 0; x < width; x++) {
            lx_ref_texel *tx = &out->texels[(size_t)y * width + x];
            double pu = (x + 0.5) / width, pv = (y + 0.5) / height;
            for (uint32_t k = 0; k < node->mesh_count && !tx->used; k++) {
                const lx_mesh *m = &scene->meshes[node->meshes[k]];
                int set = lx_ref_uv_set(m);
                if (set < 0)
                    continue;
                const lx_vec2 *uv = m->uv[set];
                for (uint32_t t = 0; t < m->triangle_count; t++) {
                    const uint32_t *i = &m->indices[3 * t];
                    double w[3];
                    if (!lx_ref_uv_barycentric(uv[i[0]], uv[i[1]], uv[i[2]], pu, pv, w))
                        continue;
                    if (!(w[0] >= 0 && w[1] >= 0 && w[2] >= 0))
                        continue;
                    tx->used = true;
                    tx->mesh = node->meshes[k];
                    tx->triangle = t;
                    memcpy(tx->bary, w, sizeof w);
                    tx->margin = fmin(w[0], fmin(w[1], w[2]));
                    double p[3] = {0, 0, 0}, n[3] = {0, 0, 0}, pw[3], nw[3];
                    for (int v = 0; v < 3; v++) {
                        double pp[3], nn[3];
                        from_vec(m->positions[i[v]], pp);
                        from_vec(m->normals[i[v]], nn);
                        for (int c = 0; c < 3; c++) {
                            p[c] += w[v] * pp[c];
                            n[c] += w[v] * nn[c];
                        }
                    }
                    d_point(&node->world, p, pw);
                    lx_ref_normalize(n);
                    d_apply3(nm, n, nw);
                    lx_ref_normalize(nw);
                    double a[3], b[3], c[3], e1[3], e2[3], g[3], gw[3];
                    from_vec(m->positions[i[0]], a);
                    from_vec(m->positions[i[1]], b);
                    from_vec(m->positions[i[2]], c);
                    d_sub(b, a, e1);
                    d_sub(c, a, e2);
                    lx_ref_cross(e1, e2, g);
                    d_apply3(nm, g, gw);
                    lx_ref_normalize(gw);
                    tx->position = to_vec(pw);
                    tx->normal = to_vec(nw);
                    tx->geometric_normal = to_vec(gw);
                    break; /* as the document: the first triangle found wins */
                }
            }
        }
}

void lx_ref_map_free(lx_ref_map *map)
{
    free(map->texels);
    memset(map, 0, sizeof *map);
}

/* ---- lighting --------------------------------------------------------------- */

float lx_ref_bias(const lx_ref_scene *rs, lx_vec3 p)
{
    float m = fmaxf(fabsf(p.x), fmaxf(fabsf(p.y), fabsf(p.z)));
    return 1e-5f * rs->diagonal + 4e-6f * m;
}

/* ---- the light model, from its formulas ------------------------------------ */

/* One light at a point, in double: what src/light's lx_light_evaluate
 * computes, written here from the model's definition (luxel/light.h) and
 * calling nothing of it. */
typedef struct ref_light_eval {
    bool direct;        /* some direct light arrives */
    double to_light[3]; /* unit, from the point toward the light */
    double distance;    /* INFINITY for a directional light */
    double e[3];        /* unshadowed illuminance (physical: lux) */
    double scale[3];    /* the same without N.L and the range falloff */
    double ambient[3];
} ref_light_eval;

/* Filament's smooth distance window (1 - (d^2 / range^2)^2)^2, 1 without a
 * range. */
static double ref_window(double d2, double range)
{
    if (!(range > 0.0))
        return 1.0;
    double f = d2 / ((double)range * range);
    double s = 1.0 - f * f;
    return s > 0.0 ? s * s : 0.0;
}

/* Filament's spot attenuation t^2, t = saturate((cos - cos outer) /
 * max(cos inner - cos outer, 1e-4)); inner == outer is a hard-edged cone. */
static double ref_spot(const lx_light *l, double cos_angle)
{
    if (l->type != LX_LIGHT_SPOT)
        return 1.0;
    double co = cos((double)l->outer_angle), ci = cos((double)l->inner_angle);
    if (!(l->inner_angle < l->outer_angle))
        return cos_angle >= co ? 1.0 : 0.0;
    double t = (cos_angle - co) / fmax(ci - co, 1e-4);
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    return t * t;
}

bool lx_ref_light_supported(const lx_light *l)
{
    return (l->type == LX_LIGHT_POINT || l->type == LX_LIGHT_SPOT ||
            l->type == LX_LIGHT_DIRECTIONAL) &&
           !l->profile;
}

static ref_light_eval ref_light(const lx_light *l, lx_vec3 pf, lx_vec3 nf)
{
    ref_light_eval r;
    memset(&r, 0, sizeof r);
    double p[3], n[3], color[3], amb[3];
    from_vec(pf, p);
    from_vec(nf, n);
    from_vec(l->color, color);
    from_vec(l->ambient, amb);
    double intensity = l->intensity, scale = 0.0, unattenuated = 0.0;
    if (l->type == LX_LIGHT_DIRECTIONAL) {
        /* lux at normal incidence; classic: (N.L)^2 I (no distance) */
        r.distance = INFINITY;
        for (int c = 0; c < 3; c++) {
            r.to_light[c] = -(double)(&l->direction.x)[c];
            r.ambient[c] = amb[c];
        }
        double ndotl = lx_ref_dot(n, r.to_light);
        if (ndotl > 0.0)
            scale = l->model == LX_MODEL_CLASSIC ? ndotl * ndotl * intensity : intensity * ndotl;
        unattenuated = intensity;
    } else {
        double pos[3], v[3];
        from_vec(l->position, pos);
        d_sub(pos, p, v);
        double d2 = lx_ref_dot(v, v), d = sqrt(d2);
        double window = ref_window(d2, l->range);
        for (int c = 0; c < 3; c++)
            r.ambient[c] = amb[c] * window;
        r.distance = d;
        if (d > 0.0) {
            for (int c = 0; c < 3; c++)
                r.to_light[c] = v[c] / d;
            double dir[3];
            from_vec(l->direction, dir);
            double ndotl = lx_ref_dot(n, r.to_light);
            double spot = ref_spot(l, -lx_ref_dot(dir, r.to_light));
            if (ndotl > 0.0 && spot > 0.0) {
                if (l->model == LX_MODEL_CLASSIC) {
                    /* the per-texel document's ((1 - d / range) |N.L|)^2 I */
                    if (d < l->range) {
                        double f = (1.0 - d / l->range) * ndotl;
                        scale = f * f * intensity * spot;
                    }
                    unattenuated = intensity * spot;
                } else {
                    /* inverse square with Filament's 1e-4 m^2 floor */
                    scale = intensity * window * spot * ndotl / fmax(d2, 1e-4);
                    unattenuated = intensity * spot / fmax(d2, 1e-4);
                }
            }
        }
    }
    r.direct = scale > 0.0;
    for (int c = 0; c < 3; c++) {
        r.e[c] = scale * color[c];
        r.scale[c] = r.direct ? unattenuated * color[c] : 0.0;
    }
    return r;
}

/* The document's blur: clamp((occluder / light distance)^power * multiplier,
 * 0, 1); no measurable light distance is fully shadowed. */
static double ref_blur(const lx_light *l, double occluder, double light_distance)
{
    if (!(light_distance > 0.0) || !(occluder >= 0.0))
        return 0.0;
    double v = pow(occluder / light_distance, (double)l->blur_power) * l->blur_multiplier;
    return v > 0.0 ? (v < 1.0 ? v : 1.0) : 0.0;
}

lx_vec3 lx_ref_shade(const lx_ref_scene *rs, const lx_light *lights, uint32_t light_count,
                     lx_vec3 ambient, lx_vec3 p, lx_vec3 n, lx_vec3 ng, double edge_eps,
                     bool *ambiguous)
{
    return lx_ref_shade_scale(rs, lights, light_count, ambient, p, n, ng, edge_eps, ambiguous,
                              NULL);
}

lx_vec3 lx_ref_shade_scale(const lx_ref_scene *rs, const lx_light *lights, uint32_t light_count,
                           lx_vec3 ambient, lx_vec3 p, lx_vec3 n, lx_vec3 ng, double edge_eps,
                           bool *ambiguous, lx_vec3 *scale)
{
    double sum[3] = {ambient.x, ambient.y, ambient.z};
    double big[3] = {ambient.x, ambient.y, ambient.z};
    bool amb = false;
    for (uint32_t l = 0; l < light_count; l++) {
        const lx_light *light = &lights[l];
        if (!lx_ref_light_supported(light)) {
            fprintf(stderr,
                    "reference: light '%.*s' (type %d%s) is not one the oracle evaluates: "
                    "point, spot and directional lights without a profile only\n",
                    (int)sizeof light->name, light->name, (int)light->type,
                    light->profile ? ", with a profile" : "");
            abort();
        }
        ref_light_eval e = ref_light(light, p, n);
        for (int c = 0; c < 3; c++) {
            sum[c] += e.ambient[c];
            big[c] += e.ambient[c] + e.scale[c];
        }
        if (!e.direct)
            continue;
        lx_vec3 to_light = to_vec(e.to_light);
        double vis = 1.0;
        if (light->shadow != LX_SHADOW_NONE) {
            double side = ng.x * e.to_light[0] + ng.y * e.to_light[1] + ng.z * e.to_light[2];
            double s = side >= 0 ? 1.0 : -1.0;
            double bias = lx_ref_bias(rs, p);
            lx_vec3 o = lx_v3((float)(p.x + s * bias * ng.x), (float)(p.y + s * bias * ng.y),
                              (float)(p.z + s * bias * ng.z));
            double tmax = isfinite(e.distance) ? e.distance - 2.0 * bias : INFINITY;
            if (tmax < 0)
                tmax = 0;
            bool a = false;
            if (light->shadow == LX_SHADOW_HARD) {
                vis = lx_ref_occluded(rs, o, to_light, 0.0, tmax, edge_eps, &a) ? 0.0 : 1.0;
            } else {
                /* the blur: nearest occluder distance / light distance */
                lx_ref_hit h;
                if (lx_ref_closest(rs, o, to_light, 0.0, tmax, edge_eps, &h, &a))
                    vis = ref_blur(light, h.t, isfinite(e.distance) ? e.distance : rs->diagonal);
            }
            amb = amb || a;
        }
        for (int c = 0; c < 3; c++)
            sum[c] += vis * e.e[c];
    }
    if (ambiguous)
        *ambiguous = amb;
    if (scale)
        *scale = to_vec(big);
    return to_vec(sum);
}

/* ---- a parallel rectangle's illuminance, from the form-factor catalogue ---- */

/* The corner case's F for the rectangle [0, X] x [0, Y] (in units of the
 * height), signed: odd in X and in Y. */
static double corner_form_factor(double X, double Y)
{
    double sx = sqrt(1.0 + X * X), sy = sqrt(1.0 + Y * Y);
    return (X / sx * atan(Y / sx) + Y / sy * atan(X / sy)) / (2.0 * 3.14159265358979323846);
}

double lx_ref_rect_parallel_illuminance(double a0, double a1, double b0, double b1, double h,
                                        double luminance)
{
    a0 /= h, a1 /= h, b0 /= h, b1 /= h;
    double f = corner_form_factor(a1, b1) - corner_form_factor(a0, b1) -
               corner_form_factor(a1, b0) + corner_form_factor(a0, b0);
    return 3.14159265358979323846 * luminance * f;
}
