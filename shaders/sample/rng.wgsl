// The counter-based random numbers of DESIGN.md §9 S3 (f32 side). Twin of src/cpu/sample/rng.rs,
// which carries the citations (Jarzynski & Olano 2020, the nested `pcg` hash).
//
// Bit-identical to the CPU: the same wrapping u32 arithmetic (WGSL's u32 `*` and `+` wrap), and
// the top 24 bits × 2⁻²⁴ are exact in f32, so both paths see the very same u.
// GPU-only rng_uniform: `uniform` is a WGSL reserved word; this is rng::uniform.
// uniform53 returns the 53 bits as two u32 words (the 32-bit hash, then the 21 bits of the next
// round), not a float: f32 cannot hold them, and the texel pick (sample/env_table.wgsl's
// cell53) uses them in exact integer arithmetic.

fn pcg_hash(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// The uniform in [0, 1) for the four keys: 24 bits, a multiple of 2⁻²⁴ (exact in f32).
fn rng_uniform(seed: u32, point: u32, sample: u32, dim: u32) -> f32 {
    let h = pcg_hash(dim + pcg_hash(sample + pcg_hash(point + pcg_hash(seed))));
    return f32(h >> 8u) * (1.0 / 16777216.0);
}

// The 53-bit uniform's bits for the four keys: (h, l) with the uniform = (h·2²¹ + l)·2⁻⁵³.
fn uniform53(seed: u32, point: u32, sample: u32, dim: u32) -> vec2<u32> {
    let h = pcg_hash(dim + pcg_hash(sample + pcg_hash(point + pcg_hash(seed))));
    return vec2<u32>(h, pcg_hash(h) >> 11u);
}
