// Whether the cells are self-propelled along a polarity (docs/model.md §11.1): the force pass
// adds each cell's propulsion to its interface force before the velocity, and
// `polarity_update` steps each cell's angle by Heun's method after each evaluation of a step,
// with the noise drawn by Philox from the same key as the host's (`mechanics::terms::NoiseKey`).
override POLARITY: u32 = 0u;
// Per cell, POL_STRIDE floats: θ, θ at the step's start, the rate there (or the stiffness
const POL_STRIDE: u32 = 8u;

// ---- polarity and its noise (mechanics::terms) ----

// (cos θ, sin θ), the argument first brought to [−π, π] (where WGSL's cos and sin are
// accurate).
fn polar(theta: f32) -> vec2<f32> {
    let t = theta - TAU * round(theta / TAU);
    return vec2<f32>(cos(t), sin(t));
}

// mechanics::terms::propulsion
fn polarity_force(magnitude: f32, eta: f32, f: vec2<f32>, theta: f32) -> vec2<f32> {
    let p = polar(theta);
    var m = magnitude;
    if (eta > 0.0 && m != 0.0) {
        let against = max(0.0, -dot(f, p));
        m *= exp(-eta * against / abs(m));
    }
    return m * p;
}

// mechanics::terms::alignment_target (`align`: Params::pol_align's code)
fn polarity_target(align: u32, v: vec2<f32>, f: vec2<f32>, s: vec2<f32>, theta: f32) -> vec2<f32> {
    if (align == 1u) {
        return v;
    }
    if (align == 2u) {
        return f;
    }
    if (align == 3u) {
        let m = length(s);
        if (m == 0.0) {
            return vec2<f32>(0.0);
        }
        let phi = 0.5 * atan2(s.y, s.x);
        let n = vec2<f32>(cos(phi), sin(phi));
        return select(m, -m, dot(n, polar(theta)) < 0.0) * n;
    }
    return vec2<f32>(0.0);
}

// mechanics::terms::alignment_rate
fn polarity_rate(rate: f32, t: vec2<f32>, theta: f32) -> f32 {
    let norm = length(t);
    if (norm > 0.0) {
        let p = polar(theta);
        return -rate * norm * atan2(t.x * p.y - t.y * p.x, dot(t, p));
    }
    return 0.0;
}

// The high and low words of the 64-bit product a·b, from 16-bit halves.
fn mul_hi_lo(a: u32, b: u32) -> vec2<u32> {
    let al = a & 0xffffu;
    let ah = a >> 16u;
    let bl = b & 0xffffu;
    let bh = b >> 16u;
    let p0 = al * bl;
    let p1 = al * bh;
    let p2 = ah * bl;
    let p3 = ah * bh;
    let mid = (p0 >> 16u) + (p1 & 0xffffu) + (p2 & 0xffffu);
    return vec2<u32>(p3 + (p1 >> 16u) + (p2 >> 16u) + (mid >> 16u), a * b);
}

// mechanics::terms::philox4x32_10
fn philox4x32_10(counter: vec4<u32>, key: vec2<u32>) -> vec4<u32> {
    var c = counter;
    var k = key;
    for (var r = 0u; r < 10u; r++) {
        if (r > 0u) {
            k = k + vec2<u32>(0x9E3779B9u, 0xBB67AE85u);
        }
        let a = mul_hi_lo(0xD2511F53u, c.x);
        let b = mul_hi_lo(0xCD9E8D57u, c.z);
        c = vec4<u32>(b.x ^ c.y ^ k.x, b.y, a.x ^ c.w ^ k.y, a.y);
    }
    return c;
}

// −ln u of the uniform u = (x + ½) 2⁻³² of a word, to f32 round-off of its value for every
// word: below ½ from u itself; above, from v = 1 − u = (¬x + ½) 2⁻³² (exact in the word, where
// u in f32 would be rounded to 2⁻²⁴ and WGSL's log is accurate only to 2⁻²¹ absolute near 1),
// as −ln(1 − v) = 2 atanh(s) = 2 (s + s³/3 + … + s¹⁹/19), s = v/(2 − v) ≤ ⅓ (the rest below
// 3⁻²¹/21, 5·10⁻¹²).
fn minus_log_uniform(x: u32) -> f32 {
    if (x < 0x80000000u) {
        return -log((f32(x) + 0.5) * 2.3283064365386963e-10);
    }
    let v = (f32(~x) + 0.5) * 2.3283064365386963e-10;
    let s = v / (2.0 - v);
    let s2 = s * s;
    var sum = 0.0;
    for (var k = 19.0; k >= 1.0; k -= 2.0) {
        sum = sum * s2 + 1.0 / k;
    }
    return 2.0 * s * sum;
}

// mechanics::terms::normal_of_words (cos(2πu) as −cos(2π(u − ½)), an argument in [−π, π])
fn normal_of_words(x2: u32, x3: u32) -> f32 {
    let u2 = (f32(x3) + 0.5) * 2.3283064365386963e-10;
    return -sqrt(2.0 * minus_log_uniform(x2)) * cos(TAU * (u2 - 0.5));
}

// The propulsion of cell `i` in this evaluation, from its angle and what the last evaluation
// of a step computed for it (its area and interface force, kept in `pol` by
// `polarity_update`), as the host's `Polarity::force` reads `CellContext::state`.
fn propulsion_of(i: u32) -> vec2<f32> {
    if (prm.pol_active == 0u) {
        return vec2<f32>(0.0);
    }
    let b = i * POL_STRIDE;
    var m = kc.alpha;
    if (prm.pol_density == 1u) {
        m *= pol[b + 4u];
    }
    return polarity_force(m, prm.pol_inhibition, vec2<f32>(pol[b + 5u], pol[b + 6u]), pol[b]);
}

// ---- the polarity's step: per cell, after each evaluation's force pass ----

// Heun's method for θ (mechanics::terms::Terms): after the first evaluation (MODE 0) the
// stiffness check, the rate r₁ and the kick b·N are kept and θ is predicted,
// θ* = θ + h r₁ + √h b N; after a corrector's, θ = θ₀ + h/2 (r₁ + r(θ*)) + √h b N. The rate
// reads this evaluation's velocity, force and shape. The noise's key: (identity, the step's
// iteration, the polarity's stage) and the seed, as on the host.
@compute @workgroup_size(256)
fn polarity_update(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= prm.n_cells || halted()) {
        return;
    }
    let c = i * CELL_STRIDE;
    use_cell(c);
    let b = i * POL_STRIDE;
    let theta = pol[b];
    var r = 0.0;
    var stiffness = 0.0;
    if (prm.pol_active == 1u && kc.align_rate != 0.0) {
        let t = polarity_target(
            prm.pol_align,
            vec2<f32>(cell[c + 7u], cell[c + 8u]),
            vec2<f32>(cell[c + 5u], cell[c + 6u]),
            vec2<f32>(cell[c + 1u], cell[c + 2u]),
            theta,
        );
        r = polarity_rate(kc.align_rate, t, theta);
        stiffness = kc.align_rate * length(t);
    }
    let h = prm.dt;
    if (MODE == 0u) {
        // Heun's step is stable while J|t| h ≤ 2 (mechanics::StepError::TermUnstable).
        if (!(stiffness * h <= 2.0)) {
            if (atomicMax(&status.failed, 3u) == 0u) {
                atomicStore(&status.cell, i);
            }
            pol[b + 2u] = stiffness;
            return;
        }
        var kick = 0.0;
        if (prm.pol_active == 1u && kc.noise != 0.0) {
            let done = atomicLoad(&status.steps);
            let lo = prm.step_lo + done;
            let hi = prm.step_hi + select(0u, 1u, lo < done);
            let w = philox4x32_10(
                vec4<u32>(bitcast<u32>(pol[b + 7u]), lo, hi, prm.pol_stage),
                vec2<u32>(prm.seed_lo, prm.seed_hi),
            );
            kick = kc.noise * normal_of_words(w.z, w.w);
        }
        pol[b + 1u] = theta;
        pol[b + 2u] = r;
        pol[b + 3u] = kick;
        pol[b] = theta + h * r + sqrt(h) * kick;
    } else {
        pol[b] = pol[b + 1u] + 0.5 * h * (pol[b + 2u] + r) + sqrt(h) * pol[b + 3u];
    }
    // What this evaluation computed, for the propulsion of the next.
    pol[b + 4u] = cell[c];
    pol[b + 5u] = cell[c + 5u];
    pol[b + 6u] = cell[c + 6u];
}
