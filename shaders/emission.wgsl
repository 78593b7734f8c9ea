// emission(light, ω): RGB radiance leaving the light along ω (DESIGN.md §3).
// Twin of src/cpu/emission.rs, which carries the spec citations.
//
// GPU-only emission_main: the kernel's entry point; it normalises ω as cpu::emission_batch
//   does, so emission() takes unit vectors on both sides.

// #import shared/record.wgsl
// #import shared/shaping.wgsl
// #import shared/texture.wgsl

// Emission along unit direction e (pointing away from the light; for a dome, toward the
// environment).
fn emission(light: Record, e: vec3<f32>) -> vec3<f32> {
    let base = light.base.xyz;
    switch light.kind {
        case KIND_DOME: {
            return base * dome_factor(light, e);
        }
        case KIND_DISTANT: {
            // A delta light (θmax = 0) has no emission; a finite cone's boundary is inclusive.
            let theta_max = light.axis.w;
            if theta_max > 0.0 && off_axis_angle(light.axis.xyz, e) <= theta_max {
                return base;
            }
            return vec3<f32>(0.0);
        }
        case KIND_RECT, KIND_DISK: {
            return surface_emission(light, e) * rect_mean(light);
        }
        case KIND_MESH: {
            // DESIGN.md §7 M3 (cpu::mesh::emission): L(e) where some front faces e, strictly
            // n·e > 0 (either side when double-sided, n·e ≠ 0). Without FLAG_MESH_FRONTS
            // (GpuPath::RadianceOnDevice) the emission is the CPU reference's, added on the
            // host; intensity always is.
            if !has_flag(light, FLAG_MESH_FRONTS) {
                return vec3<f32>(0.0);
            }
            let at = light.tex.w;
            let count = bitcast<u32>(mesh_atlas[at]);
            let double_sided = has_flag(light, FLAG_DOUBLE_SIDED);
            for (var k = 0u; k < count; k++) {
                let q = at + 1u + 3u * k;
                let c = dot(vec3<f32>(mesh_atlas[q], mesh_atlas[q + 1u], mesh_atlas[q + 2u]), e);
                if c > 0.0 || (double_sided && c != 0.0) {
                    return base * shaping(light, e);
                }
            }
            return vec3<f32>(0.0);
        }
        case KIND_CYLINDER: {
            // Some point of the side faces e unless e is parallel to the axis.
            let el = to_local_dir(light, e);
            if el.y != 0.0 || el.z != 0.0 {
                return base * shaping(light, e);
            }
            return vec3<f32>(0.0);
        }
        default: {
            // KIND_SPHERE: the outward surface faces every direction.
            return base * shaping(light, e);
        }
    }
}

// L(e) of a rect or disk before any texture: one-sided, strictly e · n > 0.
fn surface_emission(light: Record, e: vec3<f32>) -> vec3<f32> {
    if dot(e, light.normal.xyz) > 0.0 {
        return light.base.xyz * shaping(light, e);
    }
    return vec3<f32>(0.0);
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn emission_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let j = sample_index(gid);
    let step = row_step();
    for (var k = 0u; k < ROWS_PER_INVOCATION; k++) {
        let i = j + k * step;
        if j >= step || i >= params.count {
            return;
        }
        let e = normalize(load3(false, i));
        var sum = vec3<f32>(0.0);
        for (var l = params.light_first; l < params.light_end; l++) {
            add(i, l, emission(lights[l], e), &sum);
        }
        finish(i, sum);
    }
}
