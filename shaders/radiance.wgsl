// radiance(x, ω): RGB radiance arriving at x from direction ω (DESIGN.md §3).
// Twin of src/cpu/radiance.rs, which carries the spec citations.
//
// f32: the ray–shape dispatch (cpu::radiance::hits_emitting_surface) is written inline.
// GPU-only radiance_main: the kernel's entry point; it normalises ω as cpu::radiance_batch
//   does.

// #import shared/record.wgsl
// #import shared/shapes.wgsl
// #import mesh/ray.wgsl
// #import portal.wgsl
// #import emission.wgsl

fn radiance(light: Record, x: vec3<f32>, w: vec3<f32>) -> vec3<f32> {
    switch light.kind {
        case KIND_DOME: {
            // A dome's emission is indexed by the direction toward the environment (DESIGN.md
            // §3), which is w itself.
            if has_flag(light, FLAG_PORTALS) {
                // Masked (§8 P2): through the nearest portal crossed toward its +Z, else 0
                // (cpu::portal::radiance).
                let m = crossing(light.tex.w, x, w);
                if m.w == 0.0 {
                    return vec3<f32>(0.0);
                }
                return emission(light, w) * m.xyz;
            }
            return emission(light, w);
        }
        case KIND_DISTANT: {
            // The distant light's cone in direction w.
            return emission(light, -w);
        }
        case KIND_MESH: {
            // DESIGN.md §7 M3: the first triangle hit, L(−ω) on an emitting side, else 0 (the
            // mesh is opaque to its own light).
            let hit = first_hit(light, x, w);
            if hit.z > 0.0 && (hit.y > 0.0 || has_flag(light, FLAG_DOUBLE_SIDED)) {
                return light.base.xyz * shaping(light, -w);
            }
            return vec3<f32>(0.0);
        }
        default: {}
    }
    if has_flag(light, FLAG_TREAT_AS_POINT_OR_LINE) {
        return vec3<f32>(0.0);
    }
    let xl = to_local_point(light, x);
    let dl = to_local_dir(light, w);
    var hit = false;
    switch light.kind {
        case KIND_RECT: {
            hit = rect_hit(xl, dl, light.size.x, light.size.y);
        }
        case KIND_DISK: {
            hit = disk_hit(xl, dl, light.size.x);
        }
        case KIND_SPHERE: {
            hit = sphere_hit(xl, dl, light.size.x);
        }
        case KIND_CYLINDER: {
            hit = cylinder_hit(xl, dl, light.size.x, light.size.y);
        }
        default: {}
    }
    if !hit {
        return vec3<f32>(0.0);
    }
    // #if TEXTURE
    if has_flag(light, FLAG_RECT_TEXTURE) {
        // A textured rect: L(−ω) ⊙ tex(s, t) at the hit point, not the mean emission carries.
        return surface_emission(light, -w) * rect_factor(light, plane_hit(xl, dl).xy);
    }
    // #endif
    return emission(light, -w);
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn radiance_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let j = sample_index(gid);
    let step = row_step();
    for (var k = 0u; k < ROWS_PER_INVOCATION; k++) {
        let i = j + k * step;
        if j >= step || i >= params.count {
            return;
        }
        let x = load3(false, i);
        let w = normalize(load3(true, i));
        var sum = vec3<f32>(0.0);
        for (var l = params.light_first; l < params.light_end; l++) {
            add(i, l, radiance(lights[l], x, w), &sum);
        }
        finish(i, sum);
    }
}
