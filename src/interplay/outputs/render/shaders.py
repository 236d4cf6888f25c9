"""GLSL 330 sources of the preview renderer.

A sky pass (a full-screen triangle: zenith to horizon gradient, a neutral haze below the
horizon, so a scene without a floor stands in front of a backdrop rather than on an invented
one), then one lit fragment shader (hemisphere ambient + sun diffuse and specular by material,
soft shadows by percentage-closer filtering of a shadow map, a checker and an edge fade for
floors, Fresnel reflection of the sky and transmission for water, distance fog into the sky,
output gamma 2) for three vertex shaders: meshes (a model matrix, a colour and an opacity
per vertex), cords (instanced cylinders between two points) and knots, hooks and particles
(instanced spheres). Shadow-map passes reuse the vertex shaders with an empty fragment shader.
"""

SKY_FN = """
uniform vec3 u_zenith;       // linear RGB
uniform vec3 u_horizon;
uniform vec3 u_haze;         // below the horizon: what fog and the floors' edges fade into
vec3 sky(vec3 dir) {
    // the sky above the horizon; below it a uniform haze, so that a scene with no floor
    // reads as standing in front of a backdrop
    float e = dir.z;
    if (e >= 0.0) return mix(u_horizon, u_zenith, sqrt(min(e * 1.6, 1.0)));
    return mix(u_horizon, u_haze, min(-e * 12.0, 1.0));
}
"""

SKY_VS = """
#version 330
out vec2 v_ndc;
void main() {
    vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
    v_ndc = p;
    gl_Position = vec4(p, 1.0, 1.0);  // the far plane: drawn last, only where nothing is
}
"""

SKY_FS = """
#version 330
in vec2 v_ndc;
uniform mat4 u_inv_vp;
uniform vec3 u_eye;
out vec4 f_color;
""" + SKY_FN + """
void main() {
    vec4 w = u_inv_vp * vec4(v_ndc, 1.0, 1.0);
    vec3 dir = normalize(w.xyz / w.w - u_eye);
    f_color = vec4(sqrt(sky(dir)), 1.0);
}
"""

MESH_VS = """
#version 330
in vec3 in_pos;
in vec3 in_normal;
in vec4 in_color;    // linear RGB and opacity
uniform mat4 u_model;
uniform mat4 u_vp;
out vec3 v_pos;
out vec3 v_normal;
out vec4 v_color;
void main() {
    vec4 w = u_model * vec4(in_pos, 1.0);
    v_pos = w.xyz;
    v_normal = mat3(u_model) * in_normal;  // rotation + translation only: no inverse needed
    v_color = in_color;
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
uniform vec3 u_color;
uniform mat4 u_vp;
out vec3 v_pos;
out vec3 v_normal;
out vec4 v_color;
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
    v_color = vec4(u_color, 1.0);
    gl_Position = u_vp * vec4(p, 1.0);
}
"""

BALL_VS = """
#version 330
in vec3 in_pos;      // unit sphere
in vec3 in_normal;
in vec3 in_center;   // per instance (m)
uniform float u_radius;
uniform vec3 u_color;
uniform mat4 u_vp;
out vec3 v_pos;
out vec3 v_normal;
out vec4 v_color;
void main() {
    vec3 p = in_center + in_pos * u_radius;
    v_pos = p;
    v_normal = in_normal;
    v_color = vec4(u_color, 1.0);
    gl_Position = u_vp * vec4(p, 1.0);
}
"""

LIT_FS = """
#version 330
in vec3 v_pos;
in vec3 v_normal;
in vec4 v_color;
uniform vec3 u_eye;
uniform vec3 u_light_dir;    // unit, towards the sun
uniform mat4 u_light_vp;
uniform sampler2DShadow u_shadow;
uniform float u_bias;
uniform float u_offset;      // m: shadow lookups start this far off the surface
uniform int u_checker;       // 1: a floor's 0.5 m checker
uniform vec4 u_fade;         // a floor's extent x0, x1, y0, y1 (m): it fades into the sky
uniform float u_fade_w;      // m: over this width inside its edge (0: no fade)
uniform float u_rough;       // material roughness 0..1
uniform float u_metal;       // 0..1
uniform float u_glow;        // 0..1: light of its own
uniform int u_water;         // 1: Fresnel reflection of the sky, sharp sun glints
uniform float u_thin;        // 0..1: a thin sheet (cloth, a leaf) lets this share of the sun
                             // through to its far side
uniform vec2 u_fog;          // fog start, end (m from the eye)
out vec4 f_color;
""" + SKY_FN + """
float lit_fraction(vec3 p, vec3 n) {
    // normal offset: look up from just off the lit side of the surface, which keeps thin
    // cords and grazing cloth free of self-shadow stripes ("acne")
    vec3 nl = dot(n, u_light_dir) < 0.0 ? -n : n;
    vec4 lp = u_light_vp * vec4(p + nl * u_offset, 1.0);
    vec3 c = lp.xyz / lp.w * 0.5 + 0.5;
    if (any(lessThan(c, vec3(0.0))) || any(greaterThan(c, vec3(1.0)))) return 1.0;
    // one hardware 2x2 comparison, filtered bilinearly: a soft edge a texel wide. llvmpipe
    // runs every texture() of the shader for every pixel, so each tap is paid everywhere
    return texture(u_shadow, vec3(c.xy, c.z - u_bias));
}

void main() {
    vec3 n = normalize(v_normal);
    vec3 to_eye = u_eye - v_pos;
    vec3 v = normalize(to_eye);
    if (dot(n, v) < 0.0) n = -n;  // two-sided: cloth and cords seen from behind
    vec3 base = v_color.rgb;
    float alpha = v_color.a;
    if (u_checker == 1) {
        vec2 g = floor(v_pos.xy / 0.5);
        base *= mod(g.x + g.y, 2.0) < 0.5 ? 1.0 : 0.88;
    }
    float sh = lit_fraction(v_pos, n);
    float nl = dot(n, u_light_dir);
    float diff = max(nl, 0.0) + u_thin * max(-nl, 0.0);
    vec3 h = normalize(u_light_dir + v);
    float shine = mix(180.0, 6.0, u_rough);
    float spec = pow(max(dot(n, h), 0.0), shine) * mix(0.35, 0.03, u_rough);
    vec3 spec_col = mix(vec3(1.0), base, u_metal);
    vec3 ambient = base * mix(vec3(0.16, 0.15, 0.14), vec3(0.34, 0.36, 0.42), 0.5 + 0.5 * n.z);
    vec3 col = ambient + (base * diff * vec3(1.0, 0.96, 0.9) * (1.0 - 0.6 * u_metal)
                          + spec * spec_col) * sh;
    col += base * u_glow;
    if (u_water == 1) {
        // water: the sky reflected by Fresnel's law (Schlick, n = 1.33), the sun as glints;
        // what is transmitted shows the bed through it (alpha), so ripples read as shading
        float cosv = max(dot(n, v), 0.0);
        float fres = 0.02 + 0.98 * pow(1.0 - cosv, 5.0);
        vec3 refl = sky(reflect(-v, n));
        float glint = pow(max(dot(n, h), 0.0), 400.0) * 3.0 * sh;
        col = mix(col, refl, fres) + vec3(glint);
        alpha = mix(alpha, 1.0, fres);
    }
    col = 1.0 - exp(-1.6 * col);  // exposure: a lit white cloth keeps its shading, no clipping
    float fog = clamp((length(to_eye) - u_fog.x) / (u_fog.y - u_fog.x), 0.0, 1.0);
    if (u_fade_w > 0.0) {
        // a floor ends softly: no tile edge against the sky
        float edge = min(min(v_pos.x - u_fade.x, u_fade.y - v_pos.x),
                         min(v_pos.y - u_fade.z, u_fade.w - v_pos.y));
        fog = max(fog, 1.0 - clamp(edge / u_fade_w, 0.0, 1.0));
    }
    col = mix(col, u_haze, fog);
    f_color = vec4(sqrt(col), alpha);  // gamma 2 (sqrt: llvmpipe's pow costs two exps)
}
"""

POINT_VS = """
#version 330
in vec3 in_center;   // per point (m)
uniform mat4 u_vp;
uniform float u_radius;  // m
uniform float u_px;      // pixels per metre at unit distance
void main() {
    gl_Position = u_vp * vec4(in_center, 1.0);
    gl_PointSize = max(2.0, 2.0 * u_radius * u_px / gl_Position.w);
}
"""

POINT_FS = """
#version 330
uniform vec3 u_color;    // linear RGB
uniform float u_glow;
uniform vec3 u_light_dir;
out vec4 f_color;
void main() {
    // a droplet: a lit sphere seen as a disc (one vertex each, where a tessellated sphere
    // per droplet would cost llvmpipe dozens of triangles)
    vec2 d = gl_PointCoord * 2.0 - 1.0;
    float r2 = dot(d, d);
    if (r2 > 1.0) discard;
    vec3 n = vec3(d.x, -d.y, sqrt(1.0 - r2));
    float diff = max(dot(n, normalize(u_light_dir + vec3(0.0, 0.0, 0.5))), 0.0);
    vec3 col = u_color * (0.45 + 0.55 * diff + u_glow);
    col = 1.0 - exp(-1.6 * col);
    f_color = vec4(sqrt(col), 1.0);
}
"""

DEPTH_FS = """
#version 330
void main() {}
"""
