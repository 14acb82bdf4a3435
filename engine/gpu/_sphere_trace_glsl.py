"""GLSL of the sphere tracer (`engine.gpu.sphere_trace`): the ray-box clip, the fixed
Lipschitz march and the compute shader template with its three step rules.

`CLIP_GLSL` and `MARCH_GLSL` are shared with the path tracer
(`engine.gpu.path_trace`).  `MARCH_GLSL` needs ``float scene(vec3 p)``
(returning f / L) defined before it.
"""

from __future__ import annotations

__all__ = ["CLIP_GLSL", "MARCH_GLSL", "GRADIENT_GLSL", "TRACE_TEMPLATE"]

CLIP_GLSL = """
// the part [t0, t1] of the ray ro + t rd inside the box [lo, hi] (t0 > t1: no overlap)
void clip_box(vec3 ro, vec3 rd, vec3 lo, vec3 hi, inout float t0, inout float t1) {
    vec3 safe = mix(rd, vec3(1e-30), lessThan(abs(rd), vec3(1e-30)));
    vec3 ta = (lo - ro) / safe;
    vec3 tb = (hi - ro) / safe;
    vec3 tn = min(ta, tb);
    vec3 tf = max(ta, tb);
    t0 = max(t0, max(tn.x, max(tn.y, tn.z)));
    t1 = min(t1, min(tf.x, min(tf.y, tf.z)));
}
"""

MARCH_GLSL = """
// plain Lipschitz sphere tracing of sgn * scene from t (updated) while the distance is
// >= eps, t <= t_end and fewer than max_steps evaluations were made; returns the last
// distance (< eps: a hit at t) and the evaluations in n
float march_fixed(vec3 ro, vec3 rd, inout float t, float t_end, float sgn, float eps,
                  int max_steps, out int n) {
    float d = sgn * scene(ro + t * rd);
    n = 1;
    while (d >= eps && t <= t_end && n < max_steps) {
        t += d;
        d = sgn * scene(ro + t * rd);
        n++;
    }
    return d;
}
"""

GRADIENT_GLSL = """
vec3 scene_gradient(vec3 p, float h) {
    vec2 e = vec2(h, 0.0);
    return vec3(scene(p + e.xyy) - scene(p - e.xyy), scene(p + e.yxy) - scene(p - e.yxy),
                scene(p + e.yyx) - scene(p - e.yyx)) / (2.0 * h);
}
"""

# placeholders: mode, shading, clip, group, camera, library, entry, ambient, clip_glsl,
# march_glsl, gradient_glsl
TRACE_TEMPLATE = """#version 430
#define MODE {mode}
#define SHADING {shading}
#define CLIP {clip}
layout(local_size_x = {group}, local_size_y = {group}) in;
layout(rgba32f, binding = 0) writeonly uniform image2D u_trace;
layout(rgba32f, binding = 1) writeonly uniform image2D u_normal;
layout(rgba8, binding = 2) writeonly uniform image2D u_colour;
{camera}
uniform ivec2 u_offset;
uniform vec3 u_lo;
uniform vec3 u_hi;
uniform float u_far;
uniform float u_eps;
uniform float u_h;
uniform float u_omega;
uniform float u_stretch;
uniform int u_max_steps;
uniform int u_every;
uniform vec3 u_light;
uniform vec2 u_depth_range;

{library}
float scene(vec3 p) {{ return {entry}(p); }}
{clip_glsl}
{march_glsl}
{gradient_glsl}

void main() {{
    ivec2 px = u_offset + ivec2(gl_GlobalInvocationID.xy);
    if (px.x >= u_cam_size.x || px.y >= u_cam_size.y) return;
    vec3 ro = u_cam_eye;
    vec3 rd = camera_ray(px);
    float t = 0.0;
    float t_end = u_far;
#if CLIP
    clip_box(ro, rd, u_lo, u_hi, t, t_end);
#endif
    int steps = 0;        // all trial evaluations of the ray, re-trace included
    int last = 0;         // those of the last march (what max_steps limits)
    int evals = 0;
    bool hit = false;
    bool retraced = false;
    float t_entry = t;
    if (t <= t_end) {{
#if MODE == 0
        float d = march_fixed(ro, rd, t, t_end, 1.0, u_eps, u_max_steps, last);
        steps = last;
#elif MODE == 1
        float d = scene(ro + t * rd);
        steps = 1;
        float w = u_omega;
        while (d >= u_eps && t <= t_end && steps < u_max_steps) {{
            float s = w * d;
            float d_next = scene(ro + (t + s) * rd);
            steps++;
            if (s <= d || (d_next >= 0.0 && d + d_next >= s)) {{
                t += s;
                d = d_next;
            }} else {{
                w = 1.0 + 0.5 * (w - 1.0);
                if (w < 1.0 + 1.0 / 64.0) w = 1.0;
            }}
        }}
        last = steps;
#else
        float d = scene(ro + t * rd);
        steps = 1;
        bool plain = true;        // every step so far was t += d: the fixed march itself
        // one gradient estimate, then up to N accepted steps: the estimate is not inside a
        // branch, which llvmpipe would execute on every step for the masked-off lanes too
        while (d >= u_eps && t <= t_end && steps < u_max_steps) {{
            // forward differences from d, the distance at this point (3 evaluations)
            vec3 pg = ro + t * rd;
            vec3 dd = vec3(scene(pg + vec3(u_h, 0.0, 0.0)), scene(pg + vec3(0.0, u_h, 0.0)),
                           scene(pg + vec3(0.0, 0.0, u_h))) - d;
            float g = clamp(length(dd) / u_h, 1.0 / u_stretch, 1.0);
            if (g > 1.0 - 1.0 / 1024.0) g = 1.0;     // an exact distance: the bound itself
            evals += 3;
            int accepted = 0;
            while (accepted < u_every && d >= u_eps && t <= t_end && steps < u_max_steps) {{
                plain = plain && g == 1.0;
                float s = g == 1.0 ? d : d / g;
                float d_next = scene(ro + (t + s) * rd);
                steps++;
                if (s <= d || d_next >= 0.0) {{
                    t += s;
                    d = d_next;
                    accepted++;
                }} else {{
                    g = min(1.0, 2.0 * g);      // a sign change: halve the step
                }}
            }}
        }}
        last = steps;
#endif
#if MODE != 0
        // no hit (the box exit, far or max_steps): the whole ray again with the fixed rule,
        // the same march as MODE 0, so no ray misses what the fixed rule hits (not needed
        // where the adaptive march only made fixed steps: it was that march)
#if MODE == 2
        if (!(d < u_eps) && !plain) {{
#else
        if (!(d < u_eps)) {{
#endif
            retraced = true;
            t = t_entry;
            d = march_fixed(ro, rd, t, t_end, 1.0, u_eps, u_max_steps, last);
            steps += last;
        }}
#endif
        hit = d < u_eps;
        evals += steps;
    }}
    vec3 n = vec3(0.0);
    vec4 colour = vec4(0.0);
    float flags = 0.0;
    if (hit) {{
        vec3 gr = scene_gradient(ro + t * rd, u_h);
        float len = length(gr);
        n = len > 0.0 ? gr / len : vec3(0.0);
        flags = 1.0;
#if SHADING == 0
        colour = vec4(0.5 * n + 0.5, 1.0);
#elif SHADING == 1
        colour = vec4(vec3({ambient} + (1.0 - {ambient}) * max(dot(n, u_light), 0.0)), 1.0);
#else
        float z = (t - u_depth_range.x) / max(u_depth_range.y - u_depth_range.x, 1e-30);
        colour = vec4(vec3(1.0 - clamp(z, 0.0, 1.0)), 1.0);
#endif
    }} else if (last >= u_max_steps && t <= t_end) {{
        flags = 2.0;
    }}
    imageStore(u_trace, px, vec4(t, float(steps), float(evals), flags));
    imageStore(u_normal, px, vec4(n, retraced ? 1.0 : 0.0));
    imageStore(u_colour, px, colour);
}}
"""
