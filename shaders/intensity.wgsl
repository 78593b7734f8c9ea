// intensity(light, ω): far-field RGB intensity ∫ L cos dA along ω (DESIGN.md §3).
// Twin of src/cpu/intensity.rs, which carries the derivation.
//
// GPU-only intensity_main: the kernel's entry point; it normalises ω as
//   cpu::intensity_batch does.

// #import shared/record.wgsl
// #import shared/math.wgsl
// #import emission.wgsl

// The emitting surface's projected area along unit direction e: |det M| times the local
// shape's projected area along M⁻¹e.
fn projected_area(light: Record, e: vec3<f32>) -> f32 {
    let v = to_local_dir(light, e);
    var a = 0.0;
    switch light.kind {
        case KIND_RECT: {
            a = 4.0 * light.size.x * light.size.y * max(-v.z, 0.0);
        }
        case KIND_DISK: {
            a = PI * light.size.x * light.size.x * max(-v.z, 0.0);
        }
        case KIND_SPHERE: {
            a = PI * light.size.x * light.size.x * length(v);
        }
        case KIND_CYLINDER: {
            a = 4.0 * light.size.x * light.size.y * length(v.yz);
        }
        // Distant and dome lights: 0 (at infinity). Mesh lights: 0, their intensity is the
        // host's (GpuPath::HostIntensity), though their emission is the kernel's.
        default: {}
    }
    return a * light.irr.y;
}

fn intensity(light: Record, e: vec3<f32>) -> vec3<f32> {
    return emission(light, e) * projected_area(light, e);
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn intensity_main(@builtin(global_invocation_id) gid: vec3<u32>) {
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
            add(i, l, intensity(lights[l], e), &sum);
        }
        finish(i, sum);
    }
}
