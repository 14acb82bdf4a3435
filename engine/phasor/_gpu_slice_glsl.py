"""GLSL source of the phasor-slice compute shader (kept in Python: no package data).

One work group is one ``BIN x BIN`` pixel square of a tile; it loops over
that bin's list of kernels (see :mod:`engine.phasor._slice_bins`).  The loop
bounds and list entries are the same for the whole group, so the driver
can load the kernel data once per SIMD batch instead of per pixel.  The
buffer layout is described in :mod:`engine.phasor.gpu_slice`.
:func:`compute_source` unrolls the per-pixel code; the caller prepends
``#version 430`` and the defines BIN, PIX, GROUP_X (= BIN / PIX), CAPACITY,
FRAME_EPS and, for the filtered kernels (eq. 14-16), FILTERED.
"""

COMPUTE = """
// Each invocation does PIX pixels of a row, so every kernel entry loaded
// from the buffers serves PIX pixels.
layout(local_size_x = GROUP_X, local_size_y = BIN) in;

struct Site {
    int foot;     // pixel of the kernel's foot, tile-relative: column in the low 16 bits, row in the high
    float du;     // foot minus that pixel's centre along u, mm
    float dv;     // ... along v, mm
    float depth;  // signed distance to the plane along n = u x v, mm
};
layout(std140, binding = 0) uniform Sites { Site site[CAPACITY]; };
// xyz = f_j d_kj in the (u, v, n) basis, cycles/mm; w = phi_kj / 2 pi - g_n depth mod 1, cycles.
layout(std140, binding = 1) uniform OscV { vec4 osc_v[CAPACITY]; };
layout(std140, binding = 2) uniform OscW { vec4 osc_w[CAPACITY]; };
// The kernels of bin b are site[bin_items[e]] for bin_start[b] <= e < bin_start[b + 1].
layout(std430, binding = 3) readonly buffer BinStart { int bin_start[]; };
layout(std430, binding = 4) readonly buffer BinItems { int bin_items[]; };
// (Re G_v, Im G_v, Re G_w, Im G_w) per tile pixel, accumulated over kernel chunks.
layout(rgba32f, binding = 0) uniform image2D u_out;

uniform ivec2 u_size;     // tile width, height in pixels
uniform int u_accumulate; // 0 for the first chunk of a tile
uniform vec2 u_pixel;     // mm per column, per row
uniform float u_reach2;   // squared truncation radius, mm^2
uniform float u_env;      // Gaussian coefficient of |r|^2, mm^-2

#ifdef FILTERED
uniform float u_delta_coef;  // pi^2 / (a + b)
uniform float u_shift;       // b / (a + b)
uniform sampler3D u_fields;  // (Dx, Dy, Dz, F), [z][y][x] texels at cell centres
uniform sampler3D u_atten;   // A in [0, 1] on the same grid (all 1 when not given)
uniform vec3 u_tile_origin;  // centre of the tile's pixel [0, 0] in texel units (x, y, z)
uniform vec3 u_tex_step_u;   // texel units per column
uniform vec3 u_tex_step_v;   // texel units per row
uniform ivec3 u_field_n;     // texels along x, y, z
uniform vec3 u_axis_u;       // plane basis (world), to express q in (u, v, n)
uniform vec3 u_axis_v;
uniform vec3 u_axis_n;
#endif

// exp(i 2 pi t): t is reduced to [-1/2, 1/2] cycles, sin and cos of pi t come
// from near-minimax polynomials (|error| < 4e-9 on that range, fitted for
// this file), then the double-angle formulas give 2 pi t.  One shared
// reduction instead of two library calls; |error| ~ 5e-7 in float32,
// about twice the error of cos() and sin() on 2 pi t.
vec2 phasor(float t) {
    float x = t - round(t);
    float y = x * x;
    float s = x * (3.14159258 + y * (-5.16770688 + y * (2.55003138 + y * (-0.59804519 + y * 0.07722015))));
    float c = 1.0 + y * (-4.93480214 + y * (4.05870917 + y * (-1.33521207 + y * (0.23493762 + y * -0.02439681))));
    return vec2((c - s) * (c + s), 2.0 * s * c);
}

#ifdef FILTERED
struct Local { vec3 q_v; vec3 q_w; float atten; };

// Trilinear blend of texels clamped to the cell-centre hull, as
// engine.phasor.fields.trilinear (weights in full float, not the
// texture unit's reduced-precision LINEAR filter).
Local local_fields(vec3 u) {
    u = clamp(u, vec3(0.0), vec3(u_field_n - 1));
    ivec3 i0 = min(ivec3(floor(u)), u_field_n - 1);
    ivec3 i1 = min(i0 + 1, u_field_n - 1);
    vec3 t = u - vec3(i0);
    vec4 df = vec4(0.0);
    float a = 0.0;
    for (int c = 0; c < 8; ++c) {
        bvec3 s = bvec3((c & 1) != 0, (c & 2) != 0, (c & 4) != 0);
        ivec3 idx = ivec3(s.x ? i1.x : i0.x, s.y ? i1.y : i0.y, s.z ? i1.z : i0.z);
        vec3 w3 = mix(1.0 - t, t, s);
        float w = w3.x * w3.y * w3.z;
        df += w * texelFetch(u_fields, idx, 0);
        a += w * texelFetch(u_atten, idx, 0).r;
    }
    vec3 d = df.xyz;
    float n = length(d);
    if (n < 1e-9) {  // opposing neighbours cancelled: nearest cell's direction
        d = texelFetch(u_fields, ivec3(roundEven(u)), 0).xyz;
        n = length(d);
    }
    d /= n;
    // v = z x D and w = v x D, both unit (engine.phasor.sampling.local_frame);
    // where D is vertical, v is the x axis made orthogonal to D.
    vec3 v = vec3(-d.y, d.x, 0.0);
    float nv = length(v);
    if (nv < FRAME_EPS) {
        v = vec3(1.0, 0.0, 0.0) - d.x * d;
        nv = length(v);
    }
    v /= nv;
    vec3 w = normalize(cross(v, d));
    Local l;
    l.q_v = df.w * vec3(dot(v, u_axis_u), dot(v, u_axis_v), dot(v, u_axis_n));
    l.q_w = df.w * vec3(dot(w, u_axis_u), dot(w, u_axis_v), dot(w, u_axis_n));
    l.atten = clamp(a, 0.0, 1.0);  // trilinear weights may round a hair outside
    return l;
}
#endif

// Contribution (Re, Im of G_v; Re, Im of G_w) of one kernel at in-plane offset (a, c).
#ifdef FILTERED
vec4 term(float a, float c, float depth, vec4 ov, vec4 ow, Local l) {
#else
vec4 term(float a, float c, float depth, vec4 ov, vec4 ow) {
#endif
    float r2 = a * a + c * c + depth * depth;
    // A select, not a branch: llvmpipe runs masked lanes anyway.
    float inside = r2 < u_reach2 ? 1.0 : 0.0;
#ifdef FILTERED
    vec3 r = vec3(a, c, -depth);
    vec3 dv = l.atten * (ov.xyz - l.q_v);
    vec3 dw = l.atten * (ow.xyz - l.q_w);
    float er = u_env * r2;
    return vec4((inside * exp(-(er + u_delta_coef * dot(dv, dv))))
                * phasor(ov.x * a + ov.y * c + ov.w - u_shift * dot(dv, r)),
                (inside * exp(-(er + u_delta_coef * dot(dw, dw))))
                * phasor(ow.x * a + ow.y * c + ow.w - u_shift * dot(dw, r)));
#else
    float env = inside * exp(-u_env * r2);
    return env * vec4(phasor(ov.x * a + ov.y * c + ov.w), phasor(ow.x * a + ow.y * c + ow.w));
#endif
}

void store(ivec2 p, vec4 total) {
    if (p.x < u_size.x && p.y < u_size.y) {
        if (u_accumulate != 0) total += imageLoad(u_out, p);
        imageStore(u_out, p, total);
    }
}

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.x * PIX, gl_GlobalInvocationID.y);  // tile-relative
    int b = int(gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x);
    PIXEL_SETUP
    int e1 = bin_start[b + 1];
    for (int e = bin_start[b]; e < e1; ++e) {
        int j = bin_items[e];
        Site s = site[j];
        vec4 ov = osc_v[j];
        vec4 ow = osc_w[j];
        // r = x - x_j in (u, v, n): whole pixels exactly, then the sub-pixel part.
        int dx = px.x - bitfieldExtract(s.foot, 0, 16);
        float c = float(px.y - bitfieldExtract(s.foot, 16, 16)) * u_pixel.y - s.dv;
        PIXEL_TERMS
    }
    PIXEL_STORE
}
"""


def compute_source(pixels: int, filtered: bool) -> str:
    """The shader body for ``pixels`` pixels per invocation, unrolled by hand
    (the GLSL compiler does not unroll long loops, and arrays indexed in a
    loop end up in memory on llvmpipe)."""
    setup, terms, store = [], [], []
    for i in range(pixels):
        if filtered:
            setup.append(f"Local l{i} = local_fields(u_tile_origin + float(px.x + {i}) * u_tex_step_u"
                         " + float(px.y) * u_tex_step_v);")
        setup.append(f"vec4 acc{i} = vec4(0.0);")
        extra = f", l{i}" if filtered else ""
        terms.append(f"acc{i} += term(float(dx + {i}) * u_pixel.x - s.du, c, s.depth, ov, ow{extra});")
        store.append(f"store(px + ivec2({i}, 0), acc{i});")
    return (COMPUTE.replace("PIXEL_SETUP", "\n    ".join(setup))
            .replace("PIXEL_TERMS", "\n        ".join(terms))
            .replace("PIXEL_STORE", "\n    ".join(store)))
