// Sampling an untextured dome (f32), DESIGN.md §9 S2 "dome". Twin of src/cpu/sample/dome.rs.
//
// Only the untextured branches of sample_dome and pdf_dome: cosine-weighted about the normal when one is given
// (a zero normal stands for none), else uniform over the sphere. A textured dome's alias table
// stays on the host (prepare::Prepared::sample_on_host), so the rest of dome.rs has no GPU twin.
// f32: the frame is cone.wgsl's basis, the same formula as dome.rs's private basis.

// #import shared/math.wgsl
// #import sample/cone.wgsl

// The direction and its density per unit solid angle: vec4(ω, pdf).
fn sample_dome(n: vec3<f32>, u: vec2<f32>) -> vec4<f32> {
    let len = length(n);
    if len > 0.0 {
        // Malley's method: uniform on the unit disk lifted to the hemisphere about n.
        let nn = n / len;
        let r = sqrt(u.x);
        let phi = 2.0 * PI * u.y;
        let z = sqrt(max(1.0 - u.x, 0.0));
        let b = basis(nn);
        let w = normalize(b[0] * (r * cos(phi)) + b[1] * (r * sin(phi)) + nn * z);
        return vec4<f32>(w, max(dot(nn, w), 0.0) / PI);
    }
    // Uniform on the sphere: z uniform in [−1, 1] (Archimedes), φ uniform.
    let z = 1.0 - 2.0 * u.x;
    let r = sqrt(max(1.0 - z * z, 0.0));
    let phi = 2.0 * PI * u.y;
    return vec4<f32>(r * cos(phi), r * sin(phi), z, 1.0 / (4.0 * PI));
}

// The density sample_dome draws the unit world direction w with.
fn pdf_dome(n: vec3<f32>, w: vec3<f32>) -> f32 {
    let len = length(n);
    if len > 0.0 {
        return max(dot(n / len, w), 0.0) / PI;
    }
    return 1.0 / (4.0 * PI);
}
