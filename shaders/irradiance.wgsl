// irradiance(x, n): diffuse · ∫ radiance(x, ω) max(0, n·ω) dω (DESIGN.md §3).
// Twin of src/cpu/irradiance.rs, which carries the derivations and spec citations; its parts
// are the files in irradiance/, each the twin of the Rust module of the same name.
//
// f32: an unshaped rect goes to the quadrature (all positive terms) rather than Lambert's
//   formula when (d / smaller half-extent)·(d / height above its plane) exceeds
//   IRR_LAMBERT_COND (Lambert's edge terms cancel like each factor), or when it is cut by the
//   receiver's horizon (a clipped sliver cancels like its thinness).
// On the host: lights flagged FLAG_HOST_IRRADIANCE (textured rects over
//   prepare::RECT_TEXELS_ON_DEVICE texels, textured domes other than
//   latlong ones under a conformal frame with tables the device holds, masked domes whose
//   portals of different multipliers rays cross in either order (irradiance/portals.wgsl), mesh
//   lights whose triangles may hide one another, IES profiles bent by angleScale) give 0 here
//   and the host adds the CPU reference's value (prepare::Prepared::irradiance_on_host gives the
//   reasons). A textured latlong dome is integrated by rows of its texture
//   (irradiance/latlong_rows.wgsl), the optional part TEXTURE, compiled in only when such a
//   dome or a textured rect is integrated here; IES likewise only when an IES-shaped light is
//   (gpu::shaders::Features). An IES-shaped light's lines split at its profile's grid surfaces
//   (irradiance/line.wgsl) and its outer integral at their critical Ys (irradiance/critical.wgsl).
//   A textured rect's integrand carries its filtered texture, split at the texture's break
//   lines (irradiance/line.wgsl, irradiance/outer.wgsl; TEXTURE).
// Optional parts: the chart quadrature (CHART) and treatAsLine (LINE) are compiled in only for
//   scenes with a light that may need them (gpu::record::Record::features, which
//   follows this file's switch): on lavapipe the quadrature is nearly all of the pipeline's
//   compile, and each call site of the line integral is a copy of it.
// Structure (this file only): the sphere, rect, disk and cylinder cases choose their chart inside the
//   switch and chart_integral is called once after it (the CPU calls it in each case). Every
//   call site is inlined by the shader compiler, and one copy of the quadrature instead of four
//   cut lavapipe's compile time from ~10 s to ~7 s (and with the IES lookup inlined, from over
//   5 minutes to under one).
// f32: a (light, receiver) whose quadrature's loops were cut short (lavapipe only: its loops
//   stop silently after 65,535 iterations, see irr_cut in shared/record.wgsl) is NaN here, and
//   the host recomputes it on the CPU reference (query::PreparedScene::irradiance).
// f32: the receiver normal is normalised in irradiance_main (the CPU: in cpu::irradiance_batch);
//   a zero normal gives 0 on both.
// f32: the shaping's exact shortcuts (sphere_uniform, uniform_shaping: a shaped sphere or rect
//   whose shaping is 1 on every direction it is seen in is the unshaped one's closed form, any
//   shaped light whose shaping is 0 there gives 0) are taken in every call; the CPU takes them
//   at loose tolerances only (Adaptive::shortcuts: bit for bit, the reference integrates), and
//   with a margin of 1e-9 rad where the kernel's is 1e-4 rad plus the f32 rounding of the
//   direction. A shaped rect whose shaping is 1 takes Lambert's formula under the same
//   conditions as an unshaped one (IRR_LAMBERT_COND), else the quadrature.
// GPU-only irradiance_main: the kernel's entry point.

// #import shared/record.wgsl
// #import shared/math.wgsl
// #import irradiance/closed.wgsl
// #import irradiance/chart.wgsl
// #import irradiance/outer.wgsl
// #import mesh/lambert.wgsl
// #import irradiance/portals.wgsl
// #import irradiance/latlong_rows.wgsl
// #import irradiance/latlong_polygon.wgsl

fn irradiance(light: Record, x: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let base = light.base.xyz;
    var e = vec3<f32>(0.0);
    // The cases that need the chart quadrature pick their chart here and integrate once, after
    // the switch (see the header).
    var chart: Chart;
    var use_chart = false;
    if has_flag(light, FLAG_HOST_IRRADIANCE) {
        // Integrated on the host (see the header).
        return e;
    }
    switch light.kind {
        case KIND_DOME: {
            e = base * PI;
            // A textured dome is latlong under a conformal frame (prepare::gpu_path): the
            // dome-space normal is A_eff⁻¹ n normalised (src/cpu/irradiance/latlong_rows.rs).
            let inv = mat3x3<f32>(light.tex_inv0.xyz, light.tex_inv1.xyz, light.tex_inv2.xyz);
            let textured = has_flag(light, FLAG_DOME_TEXTURE);
            if has_flag(light, FLAG_PORTALS) {
                // Masked where the device sums it (prepare::gpu_path::masked): E over the
                // portals and, by inclusion–exclusion, their overlaps.
                e = base * portals_irradiance(light.tex.w, x, n, PortalDome(textured, light.tex.z, inv));
            } else if textured {
                // #if TEXTURE
                e = base * latlong_irradiance(rows_info(light.tex.z), normalize(inv * n));
                // #endif
            }
        }
        case KIND_DISTANT: {
            let c = -light.axis.xyz;
            let theta_max = light.axis.w;
            let sg = dot(n, c);
            if theta_max == 0.0 {
                e = base * max(sg, 0.0);
            } else {
                e = base * cap_irradiance(theta_max, sg, length(cross(n, c)));
            }
        }
        case KIND_SPHERE: {
            let r = light.size.x * length(light.world_x.xyz);
            // A shaped sphere whose shaping is 1 (or 0) on every direction it is seen in.
            var k = -1.0;
            if has_flag(light, FLAG_SHAPING) && has_flag(light, FLAG_SIMILARITY) {
                k = sphere_uniform(light, x, r);
            }
            if has_flag(light, FLAG_TREAT_AS_POINT_OR_LINE) {
                e = point_irradiance(light, x, n);
            } else if !has_flag(light, FLAG_SHAPING) && has_flag(light, FLAG_SIMILARITY) {
                e = base * sphere_cap(world_origin(light), r, x, n);
            } else if k >= 0.0 {
                e = base * (k * sphere_cap(world_origin(light), r, x, n));
            } else {
                chart = sphere_chart(light, x);
                use_chart = true;
            }
        }
        case KIND_RECT: {
            let xl = to_local_point(light, x);
            if xl.z < 0.0 {
                let size = min(light.size.x * length(light.world_x.xyz), light.size.y * length(light.world_y.xyz));
                // Lambert only where its sum cannot cancel much (see IRR_LAMBERT_COND), and not
                // clipped by the horizon.
                let d = length(world_origin(light) - x);
                let h = abs(dot(x - world_origin(light), light.normal.xyz));
                let lambert = d * d <= IRR_LAMBERT_COND * size * h;
                // (A textured rect's radiance varies over it: the quadrature.)
                let plain = !has_flag(light, FLAG_SHAPING) && !has_flag(light, FLAG_RECT_TEXTURE);
                chart = plane_chart(light, x, light.size.x, light.size.y, REGION_SQUARE);
                // A shaped rect whose shaping is 1 on every direction it is seen in is the
                // unshaped one (the shaping's 0 is taken below).
                var k = -1.0;
                if !plain && !has_flag(light, FLAG_RECT_TEXTURE) {
                    k = uniform_shaping(light, direction_cone(chart), x);
                }
                if (plain || k == 1.0) && lambert && rect_above_horizon(light, x, n) {
                    e = base * rect_lambert(light, x, n);
                } else {
                    use_chart = true;
                }
            }
        }
        case KIND_DISK: {
            let xl = to_local_point(light, x);
            if xl.z < 0.0 {
                chart = plane_chart(light, x, light.size.x, light.size.x, REGION_DISK);
                use_chart = true;
            }
        }
        case KIND_CYLINDER: {
            if has_flag(light, FLAG_TREAT_AS_POINT_OR_LINE) {
                // #if LINE
                e = line_irradiance(light, x, n);
                // #endif
            } else {
                chart = cylinder_chart(light, x);
                use_chart = true;
            }
        }
        case KIND_MESH: {
            // Only meshes whose triangles cannot hide one another get here
            // (GpuPath::HostIntensityOnly): Lambert's formula summed over the triangles.
            e = base * mesh_lambert(light, x, n);
        }
        default: {}
    }
    // #if CHART
    // A shaped light whose shaping is 0 on every direction it is seen in gives 0.
    if use_chart && !(has_flag(light, FLAG_SHAPING) && uniform_shaping(light, direction_cone(chart), x) == 0.0) {
        e = base * chart_integral(light, chart, n);
    }
    // #endif
    return e * light.irr.x;
}

// uniform_shaping for a sphere of world radius r (under a similarity) seen from x: its
// directions fill the cone of half-angle asin(r/d) around the centre's.
fn sphere_uniform(light: Record, x: vec3<f32>, r: f32) -> f32 {
    let w = world_origin(light) - x;
    let d = length(w);
    if !(d > r) {
        return -1.0;
    }
    return uniform_shaping(light, vec4<f32>(w / d, asin(r / d)), x);
}

// The shaping factor when it is exactly 0 or 1 on every emission direction of a light seen from
// x within `cone` (unit direction toward the light, half-angle; w < 0: none, direction_cone),
// else -1 (the CPU: None; see the CPU twin for why it is exact). Only the cone: no IES profile,
// and a focus that changes nothing (focus ≤ 0 or a white tint) for the factor 1.
fn uniform_shaping(light: Record, cone: vec4<f32>, x: vec3<f32>) -> f32 {
    if !has_flag(light, FLAG_SHAPING) || has_flag(light, FLAG_IES) || !(cone.w >= 0.0) {
        return -1.0;
    }
    // The margin covers the f32 rounding of the direction (|x|·ε relative to the distance) and
    // of the angles.
    let d = length(world_origin(light) - x);
    let margin = 1e-4 + 1e-6 * (length(x) + length(world_origin(light))) / d;
    let theta = off_axis_angle(light.axis.xyz, -cone.xyz);
    if theta - cone.w > light.cone.x + margin {
        return 0.0;
    }
    let focus_inactive = !(light.focus_tint.w > 0.0) || all(light.focus_tint.xyz == vec3<f32>(1.0));
    if focus_inactive && theta + cone.w + margin < light.cone.y && light.cone.y <= light.cone.x {
        return 1.0;
    }
    return -1.0;
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn irradiance_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    // One sample per lane_stride invocations (see Params::lane_stride): the others return.
    let lane = sample_index(gid);
    let stride = max(params.lane_stride, 1u);
    if lane % stride != 0u {
        return;
    }
    let i = lane / stride;
    if i >= params.count {
        return;
    }
    let x = load3(false, i);
    let nraw = load3(true, i);
    let len = length(nraw);
    let valid = len > 0.0;
    let n = nraw / select(1.0, len, valid);
    var sum = vec3<f32>(0.0);
    for (var l = params.light_first; l < params.light_end; l++) {
        var v = vec3<f32>(0.0);
        // Params::light_filter. Normal-only: FLAG_NORMAL_ONLY, set from
        // Prepared::irradiance_is_normal_only (a masked dome is the host's,
        // FLAG_HOST_IRRADIANCE, 0 in either pass).
        let normal_only = has_flag(lights[l], FLAG_NORMAL_ONLY);
        let which = params.light_filter & 3u;
        // LIGHTS_SKIP_TEXTURED_RECTS: a textured rect without a profile is the host's in this
        // call (query::scene host_takes: the CPU's moment path).
        let skipped = (params.light_filter & LIGHTS_SKIP_TEXTURED_RECTS) != 0u
            && has_flag(lights[l], FLAG_RECT_TEXTURE) && !has_flag(lights[l], FLAG_IES);
        let wanted = (which == LIGHTS_ALL || (which == LIGHTS_NORMAL_ONLY) == normal_only) && !skipped;
        if valid && wanted {
            irr_cut = false;
            v = irradiance(lights[l], x, n);
            if irr_cut {
                // A loop was cut short (see irr_cut in shared/record.wgsl): NaN, which the
                // host recomputes.
                v = vec3<f32>(bitcast<f32>(0x7fc00000u));
            }
        }
        add(i, l, v, &sum);
    }
    finish(i, sum);
}
