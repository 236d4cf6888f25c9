"""GLSL 330 sources of the preview renderer.

One lit fragment shader (hemisphere ambient + sun diffuse and specular, soft shadows by
percentage-closer filtering of a shadow map, an optional checker for the ground, distance
fog into the sky colour, output gamma 2.2) serves three vertex shaders: rigid and static
meshes (a model matrix), cords (instanced cylinders between two points) and knots, hooks
and particles (instanced spheres). Shadow-map passes reuse the vertex shaders with an empty
fragment shader.
"""

MESH_VS = """
#version 330
in vec3 in_pos;
in vec3 in_normal;
uniform mat4 u_model;
uniform mat4 u_vp;
out vec3 v_pos;
out vec3 v_normal;
void main() {
    vec4 w = u_model * vec4(in_pos, 1.0);
    v_pos = w.xyz;
    v_normal = mat3(u_model) * in_normal;  // rotation + translation only: no inverse needed
    gl_Position = u_vp * w;
}
"""

TUBE_VS = """
#version 330
in vec3 in_pos;      // unit cylinder: unit circle in xy, z from 0 to 1
in vec3 in_normal;
in vec3 in_a;        // per instance: the cord's two end points (m)
in vec3 in_b;
uniform float u_radius;
uniform mat4 u_vp;
out vec3 v_pos;
out vec3 v_normal;
void main() {
    vec3 d = in_b - in_a;
    float len = length(d);
    vec3 w = len > 1e-9 ? d / len : vec3(0.0, 0.0, 1.0);
    vec3 t = abs(w.z) < 0.9 ? vec3(0.0, 0.0, 1.0) : vec3(1.0, 0.0, 0.0);
    vec3 u = normalize(cross(w, t));
    vec3 v = cross(w, u);
    vec3 p = in_a + (u * in_pos.x + v * in_pos.y) * u_radius + d * in_pos.z;
    v_pos = p;
    v_normal = u * in_normal.x + v * in_normal.y;
    gl_Position = u_vp * vec4(p, 1.0);
}
"""

BALL_VS = """
#version 330
in vec3 in_pos;      // unit sphere
in vec3 in_normal;
in vec3 in_center;   // per instance (m)
uniform float u_radius;
uniform mat4 u_vp;
out vec3 v_pos;
out vec3 v_normal;
void main() {
    vec3 p = in_center + in_pos * u_radius;
    v_pos = p;
    v_normal = in_normal;
    gl_Position = u_vp * vec4(p, 1.0);
}
"""

LIT_FS = """
#version 330
in vec3 v_pos;
in vec3 v_normal;
uniform vec3 u_color;        // linear RGB
uniform vec3 u_eye;
uniform vec3 u_light_dir;    // unit, towards the sun
uniform mat4 u_light_vp;
uniform sampler2DShadow u_shadow;
uniform float u_spread;      // penumbra width in shadow-map uv units
uniform float u_bias;
uniform float u_offset;      // m: shadow lookups start this far off the surface
uniform int u_checker;       // 1: the ground's 0.5 m checker
uniform vec3 u_sky;          // linear RGB of the background
uniform vec2 u_fog;          // fog start, end (m from the eye)
out vec4 f_color;

float lit_fraction(vec3 p, vec3 n) {
    // normal offset: look up from just off the lit side of the surface, which keeps thin
    // cords and grazing cloth free of self-shadow stripes ("acne")
    vec3 nl = dot(n, u_light_dir) < 0.0 ? -n : n;
    vec4 lp = u_light_vp * vec4(p + nl * u_offset, 1.0);
    vec3 c = lp.xyz / lp.w * 0.5 + 0.5;
    if (any(lessThan(c, vec3(0.0))) || any(greaterThan(c, vec3(1.0)))) return 1.0;
    // four taps, each a hardware 2x2 comparison (bilinear PCF), on a rotated grid across the
    // penumbra: llvmpipe runs every texture() of the shader for every pixel (it does not
    // branch around them), so the tap count is the cost
    float z = c.z - u_bias;
    vec2 a = vec2(0.38, 0.13) * u_spread;
    vec2 b = vec2(-0.13, 0.38) * u_spread;
    return 0.25 * (texture(u_shadow, vec3(c.xy + a, z)) + texture(u_shadow, vec3(c.xy - a, z))
                 + texture(u_shadow, vec3(c.xy + b, z)) + texture(u_shadow, vec3(c.xy - b, z)));
}

void main() {
    vec3 n = normalize(v_normal);
    vec3 v = normalize(u_eye - v_pos);
    if (dot(n, v) < 0.0) n = -n;  // two-sided: cloth and cords seen from behind
    vec3 base = u_color;
    if (u_checker == 1) {
        vec2 g = floor(v_pos.xy / 0.5);
        base *= mod(g.x + g.y, 2.0) < 0.5 ? 1.0 : 0.82;
    }
    float sh = lit_fraction(v_pos, n);
    float diff = max(dot(n, u_light_dir), 0.0);
    vec3 h = normalize(u_light_dir + v);
    float spec = pow(max(dot(n, h), 0.0), 40.0) * 0.2;
    vec3 ambient = base * mix(vec3(0.16, 0.15, 0.14), vec3(0.34, 0.36, 0.42), 0.5 + 0.5 * n.z);
    vec3 col = ambient + (base * diff * vec3(1.0, 0.96, 0.9) + spec) * sh;
    col = 1.0 - exp(-1.6 * col);  // exposure: a lit white cloth keeps its shading, no clipping
    float fog = clamp((length(u_eye - v_pos) - u_fog.x) / (u_fog.y - u_fog.x), 0.0, 1.0);
    col = mix(col, u_sky, fog);
    f_color = vec4(pow(col, vec3(1.0 / 2.2)), 1.0);  // gamma 2.2
}
"""

DEPTH_FS = """
#version 330
void main() {}
"""
