//! Each WGSL function of the kernels (`wgsl/`) that implements an equation against its Rust reference
//! (`mechanics::equations`, `phasefield::EnergyCoefficients`), on random inputs, for both
//! pressure forms: so that every formula keeps one reference, and a GPU formula that drifts
//! from it fails here by name.
//!
//! A small kernel appended to the step's own source calls each function on a table of
//! inputs; the references take the same f32 inputs in f64.

use mechanics::{equations as eq, PressureKind};
use phasefield::{EnergyCoefficients, EnergyParams, Lattice, PatchShape};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use wgpu::util::DeviceExt;

mod common;

/// Inputs per sample: φ, ∇²φ, area, Σ_{j≠i} φ_j², ∂_xφ, ∂_yφ, Q_xx, Q_xy, s1, s2, u,
/// v_x, v_y, R_old, R_new, Δt.
const IN: usize = 16;
/// Outputs per sample, in the order of `NAMES`.
const OUT: usize = 22;
const NAMES: [&str; OUT] = [
    "area_factor",
    "free_energy_derivative",
    "shape_tensor_density.xx",
    "shape_tensor_density.xy",
    "pressure_cell_part",
    "pressure",
    "pressure_self_part",
    "force_density.x",
    "force_density.y",
    "velocity.x",
    "velocity.y",
    "rhs",
    "heun_predictor",
    "heun_corrector",
    "pressure_regrouped",
    "laplacian",
    "pressure_own_part",
    "wall_derivative",
    "wall_pressure",
    "adhesion_derivative",
    "adhesion_pressure_cell_part",
    "adhesion_pressure",
];

const HARNESS: &str = r#"
@group(1) @binding(0) var<storage, read> eq_in: array<f32>;
@group(1) @binding(1) var<storage, read_write> eq_out: array<f32>;

@compute @workgroup_size(64)
fn equations(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= arrayLength(&eq_out) / 22u) {
        return;
    }
    // The cell's constants, which the equations read (`use_cell` in the step): the tissue's.
    kc = Kind(prm.double_well, prm.gradient, prm.area, prm.inv_target_area, prm.xi, 1.0, 0.0, 0.0, 0.0, 0u, 0u, 0u);
    let x = i * 16u;
    let phi = eq_in[x];
    let lap = eq_in[x + 1u];
    let area = eq_in[x + 2u];
    let others = eq_in[x + 3u];
    let g = vec2<f32>(eq_in[x + 4u], eq_in[x + 5u]);
    let q = vec2<f32>(eq_in[x + 6u], eq_in[x + 7u]);
    let s1 = eq_in[x + 8u];
    let s2 = eq_in[x + 9u];
    let u = eq_in[x + 10u];
    let v = vec2<f32>(eq_in[x + 11u], eq_in[x + 12u]);
    let r_old = eq_in[x + 13u];
    let r_new = eq_in[x + 14u];
    let dt = eq_in[x + 15u];
    let af = area_factor(area);
    let o = i * 22u;
    eq_out[o] = af;
    eq_out[o + 1u] = free_energy_derivative(phi, lap, af, others);
    let sh = shape_tensor_density(g);
    eq_out[o + 2u] = sh.x;
    eq_out[o + 3u] = sh.y;
    eq_out[o + 4u] = pressure_cell_part(phi, lap, af);
    eq_out[o + 5u] = pressure(s1, s2, u);
    eq_out[o + 6u] = pressure_self_part(phi);
    let fd = force_density(u, prm.zeta, q, g);
    eq_out[o + 7u] = fd.x;
    eq_out[o + 8u] = fd.y;
    let vel = velocity(v, prm.xi);
    eq_out[o + 9u] = vel.x;
    eq_out[o + 10u] = vel.y;
    eq_out[o + 11u] = rhs(v, g, r_old);
    eq_out[o + 12u] = heun_predictor(phi, dt, r_old);
    eq_out[o + 13u] = heun_corrector(phi, dt, r_old, r_new);
    // The regrouped pressure with s3 = s4 = 0 and own = u is `pressure` less nothing but
    // the cell's own repulsion: checked against the sum of the Rust parts below.
    eq_out[o + 14u] = pressure_regrouped(s1, s2, lap, others, u);
    var st: Stencil;
    st.c = phi;
    st.xm = eq_in[x + 4u];
    st.xp = eq_in[x + 5u];
    st.ym = eq_in[x + 6u];
    st.yp = eq_in[x + 7u];
    eq_out[o + 15u] = laplacian(st);
    // The lattice pass's own part of the pressure (the gather's).
    eq_out[o + 16u] = pressure_own_part(phi, lap, af);
    // The walls' parts, with w = the `others` input and ∇²w = the Laplacian's.
    eq_out[o + 17u] = wall_derivative(phi, others, lap);
    eq_out[o + 18u] = wall_pressure(s1, s2, others, lap);
    // Adhesion's parts, with ∇²s1 = the `others` input.
    eq_out[o + 19u] = adhesion_derivative(others, lap);
    eq_out[o + 20u] = adhesion_pressure_cell_part(phi, lap);
    eq_out[o + 21u] = adhesion_pressure(s1, others);
}
"#;

/// The walls' coefficients in the harness (`wall_coefficients(1, 0.02, 2.5)`).
const WALL: [f64; 2] = [0.8, 0.1];
/// The adhesion coefficient in the harness (`adhesion_coefficient(0.015, 2.5)`).
const ADHESION: f64 = 0.075;

/// The kernel's uniform block (the shader's `Params`, one definition for Rust and WGSL),
/// with the coefficients of `coef`.
fn params_bytes(coef: &EnergyCoefficients, zeta: f32, xi: f32) -> Vec<u8> {
    let p = gpu::Params {
        double_well: coef.double_well as f32,
        gradient: coef.gradient as f32,
        area: coef.area as f32,
        inv_target_area: coef.inv_target_area as f32,
        repulsion: coef.repulsion as f32,
        zeta,
        xi,
        dt: 0.1,
        wall_repulsion: WALL[0] as f32,
        wall_adhesion: WALL[1] as f32,
        adhesion: ADHESION as f32,
        ..bytemuck::Zeroable::zeroed()
    };
    bytemuck::bytes_of(&p).to_vec()
}

fn run_kernel(
    device: &gpu::Device,
    kind: PressureKind,
    coef: &EnergyCoefficients,
    zeta: f32,
    xi: f32,
    input: &[f32],
) -> Vec<f32> {
    let shape = PatchShape::new(Lattice::new(64, 64), 8).unwrap();
    let source = gpu::shader_source(&shape, kind, 32) + HARNESS;
    let params = params_bytes(coef, zeta, xi);
    let out = run_harness(
        device,
        &source,
        "equations",
        Some(&params),
        bytemuck::cast_slice(input),
        input.len() / IN * OUT,
    );
    bytemuck::cast_slice(&out).to_vec()
}

/// Runs the entry point `entry` of `source` over its input array (`@group(1) @binding(0)`)
/// into `out_words` 32-bit words (`@group(1) @binding(1)`), one invocation per 64 words out
/// and fewer, with `params` as the uniform block `prm` where the kernel reads it.
fn run_harness(
    device: &gpu::Device,
    source: &str,
    entry: &str,
    params: Option<&[u8]>,
    input: &[u8],
    out_words: usize,
) -> Vec<u32> {
    let (d, q) = device.raw();
    let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(entry),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let pipeline = d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(entry),
        layout: None,
        module: &module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    });
    let inp = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: input,
        usage: wgpu::BufferUsages::STORAGE,
    });
    let bytes = (out_words * 4) as u64;
    let out = d.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: bytes,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let staging = d.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: bytes,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let g0 = params.map(|params| {
        let prm = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: None,
            contents: params,
            usage: wgpu::BufferUsages::UNIFORM,
        });
        d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: prm.as_entire_binding(),
            }],
        })
    });
    let g1 = d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(1),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: inp.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: out.as_entire_binding(),
            },
        ],
    });
    let mut enc = d.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        if let Some(g0) = &g0 {
            pass.set_bind_group(0, g0, &[]);
        }
        pass.set_bind_group(1, &g1, &[]);
        pass.dispatch_workgroups((out_words as u32).div_ceil(64), 1, 1);
    }
    enc.copy_buffer_to_buffer(&out, 0, &staging, 0, bytes);
    q.submit(Some(enc.finish()));
    staging
        .slice(..)
        .map_async(wgpu::MapMode::Read, |r| r.unwrap());
    d.poll(wgpu::PollType::wait_indefinitely()).unwrap();
    let data = staging.slice(..).get_mapped_range().unwrap();
    bytemuck::cast_slice(&data).to_vec()
}

/// The Rust references on one sample, in the order of `NAMES`, and for each the sum of the
/// magnitudes of its terms (the scale of its f32 round-off).
fn reference(
    kind: PressureKind,
    c: &EnergyCoefficients,
    zeta: f64,
    xi: f64,
    x: &[f64],
) -> [(f64, f64); OUT] {
    let [phi, lap, area, others, gx, gy, qxx, qxy, s1, s2, u, vx, vy, r_old, r_new, dt] =
        x.try_into().unwrap();
    let af = c.area_factor(area);
    let g = [gx, gy];
    let sh = eq::shape_tensor_density(g);
    let fd = eq::force_density(u, zeta, [qxx, qxy], g);
    let vel = eq::velocity([vx, vy], xi);
    let dw = c.double_well * (phi * (1.0 - phi) * (1.0 - 2.0 * phi)).abs();
    // The regrouped pressure with s3 = ∇²φ and s4 = Σφ_j² stood in for: (2κ/λ)(s1 s2 − s3)
    // + own (paper), (2κ/λ)(s2² − s4) + own (interaction), which equals `pressure` of
    // `u − (2κ/λ) s3` or `u − (2κ/λ) s4`.
    let (regrouped, reg_scale) = match kind {
        PressureKind::Paper => (
            eq::pressure(kind, c, s1, s2, u - c.repulsion * lap),
            c.repulsion * (s1 * s2).abs() + c.repulsion * lap.abs() + u.abs(),
        ),
        PressureKind::Interaction => (
            eq::pressure(kind, c, s1, s2, u - c.repulsion * others),
            c.repulsion * s2 * s2 + c.repulsion * others.abs() + u.abs(),
        ),
    };
    let p_scale = match kind {
        PressureKind::Paper => c.repulsion * (s1 * s2).abs() + u.abs(),
        PressureKind::Interaction => c.repulsion * s2 * s2 + u.abs(),
    };
    let cell_scale = c.repulsion * phi.abs().powi(4).max(phi.abs().powi(3))
        + dw
        + c.gradient * lap.abs()
        + (af * phi).abs();
    // The stencil of the harness: xm = ∂_xφ's slot and so on (any four numbers do).
    let nb = [gx, gy, qxx, qxy];
    let lap5 = nb.iter().map(|v| v - phi).sum::<f64>();
    [
        (af, c.area * (1.0 + (area * c.inv_target_area).abs())),
        (
            c.free_energy_derivative(phi, lap, af, others),
            dw + c.gradient * lap.abs() + (af * phi).abs() + c.repulsion * (phi * others).abs(),
        ),
        (sh[0], 0.5 * (gx * gx + gy * gy)),
        (sh[1], (gx * gy).abs()),
        (eq::pressure_cell_part(kind, c, phi, lap, af), cell_scale),
        (eq::pressure(kind, c, s1, s2, u), p_scale),
        (eq::pressure_self_part(kind, c, phi), dw),
        (
            fd[0],
            (u * gx).abs() + zeta.abs() * ((qxx * gx).abs() + (qxy * gy).abs()),
        ),
        (
            fd[1],
            (u * gy).abs() + zeta.abs() * ((qxy * gx).abs() + (qxx * gy).abs()),
        ),
        (vel[0], (vx / xi).abs()),
        (vel[1], (vy / xi).abs()),
        (
            eq::rhs([vx, vy], g, r_old),
            (vx * gx).abs() + (vy * gy).abs() + r_old.abs(),
        ),
        (
            eq::heun_predictor(phi, dt, r_old),
            phi.abs() + (dt * r_old).abs(),
        ),
        (
            eq::heun_corrector(phi, dt, r_old, r_new),
            phi.abs() + (dt * (r_old.abs() + r_new.abs())),
        ),
        (regrouped, reg_scale),
        (lap5, nb.iter().map(|v| (v - phi).abs()).sum::<f64>()),
        // `pressure_cell_part` less its repulsion term, −(2κ/λ)φ³ (paper) or −(2κ/λ)φ⁴
        // (interaction, where nothing is left).
        (
            eq::pressure_cell_part(kind, c, phi, lap, af)
                + c.repulsion
                    * match kind {
                        PressureKind::Paper => phi.powi(3),
                        PressureKind::Interaction => phi.powi(4),
                    },
            cell_scale,
        ),
        (
            eq::wall_derivative(WALL, phi, others, lap),
            WALL[0] * (phi * others * others).abs() + WALL[1] * lap.abs(),
        ),
        (
            eq::wall_pressure(WALL, s1, s2, others, lap),
            WALL[0] * (others * others * s2).abs() + WALL[1] * (lap * s1).abs(),
        ),
        (
            eq::adhesion_derivative(ADHESION, others, lap),
            ADHESION * (others.abs() + lap.abs()),
        ),
        (
            eq::adhesion_pressure_cell_part(ADHESION, phi, lap),
            ADHESION * (phi * lap).abs(),
        ),
        (
            eq::adhesion_pressure(ADHESION, s1, others),
            ADHESION * (s1 * others).abs(),
        ),
    ]
}

fn sample(rng: &mut ChaCha8Rng) -> [f32; IN] {
    let mut s = [0.0f32; IN];
    let ranges: [(f32, f32); IN] = [
        (-0.1, 1.1),   // φ
        (-0.5, 0.5),   // ∇²φ
        (0.0, 100.0),  // area
        (0.0, 2.0),    // Σ others²
        (-0.6, 0.6),   // ∂_xφ
        (-0.6, 0.6),   // ∂_yφ
        (-3.0, 3.0),   // Q_xx
        (-3.0, 3.0),   // Q_xy
        (0.0, 2.5),    // s1
        (0.0, 2.0),    // s2
        (-0.2, 0.2),   // u
        (-0.01, 0.01), // v_x
        (-0.01, 0.01), // v_y
        (-0.05, 0.05), // R_old
        (-0.05, 0.05), // R_new
        (0.05, 1.0),   // Δt
    ];
    for (v, (lo, hi)) in s.iter_mut().zip(ranges) {
        *v = rng.random_range(lo..hi);
    }
    s
}

/// f32 round-off of a formula of at most a dozen operations: a few ulps (2⁻²⁴ ≈ 6e-8 each)
/// of the sum of its terms' magnitudes; 16 ulps is the bound, and a wrong coefficient, sign
/// or term is off by far more (the smallest term of any function here is above 1e-4 of its
/// scale on these ranges).
const ULPS: f64 = 16.0 * f32::EPSILON as f64 / 2.0;

#[test]
#[cfg_attr(
    no_vulkan_driver,
    ignore = "no Vulkan driver was installed when the tests were built (apt-get install mesa-vulkan-drivers libvulkan1, then build again)"
)]
fn every_wgsl_equation_matches_its_rust_reference() {
    let Some(device) = common::try_device() else {
        return;
    };
    let coef = EnergyParams::paper().coefficients();
    let (zeta, xi) = (0.005f32, 1.0f32);
    let mut rng = ChaCha8Rng::seed_from_u64(29);
    let n = 4096;
    let input: Vec<f32> = (0..n).flat_map(|_| sample(&mut rng)).collect();
    for kind in [PressureKind::Paper, PressureKind::Interaction] {
        let out = run_kernel(&device, kind, &coef, zeta, xi, &input);
        let mut worst = [0.0f64; OUT];
        for (x, o) in input.chunks_exact(IN).zip(out.chunks_exact(OUT)) {
            let xf: Vec<f64> = x.iter().map(|&v| f64::from(v)).collect();
            let refs = reference(kind, &coef, f64::from(zeta), f64::from(xi), &xf);
            for (k, ((want, scale), &got)) in refs.iter().zip(o).enumerate() {
                let err = (f64::from(got) - want).abs() / scale.max(f64::MIN_POSITIVE);
                worst[k] = worst[k].max(err);
                assert!(
                    err <= ULPS,
                    "{kind:?}: {} = {got:e} on the GPU, {want:e} in Rust (inputs {x:?}): {err:.2e} of its scale",
                    NAMES[k]
                );
            }
        }
        for (name, w) in NAMES.iter().zip(worst) {
            println!("{kind:?}: {name}: worst error {w:.2e} of its scale (bound {ULPS:.1e})");
        }
    }
}

/// The polarity's functions and Philox's (`mechanics::terms`): per sample, in 32-bit words,
/// θ, f, v, S, a magnitude, η and J (as f32 bits), then Philox's counter and key.
const POLARITY_IN: usize = 16;
/// Per sample: the propulsion (2), the alignment targets for the velocity, the force and the
/// shape (2 each), the rate towards each (3), Philox's four words and the normal deviate of
/// the last two.
const POLARITY_OUT: usize = 16;

const POLARITY_HARNESS: &str = r#"
@group(1) @binding(0) var<storage, read> pol_in: array<u32>;
@group(1) @binding(1) var<storage, read_write> pol_out: array<u32>;

@compute @workgroup_size(64)
fn polarity_equations(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= arrayLength(&pol_out) / 16u) {
        return;
    }
    let x = i * 16u;
    let w = function_inputs(x);
    let theta = w[0];
    let f = vec2<f32>(w[1], w[2]);
    let v = vec2<f32>(w[3], w[4]);
    let s = vec2<f32>(w[5], w[6]);
    let o = i * 16u;
    let fp = polarity_force(w[7], w[8], f, theta);
    pol_out[o] = bitcast<u32>(fp.x);
    pol_out[o + 1u] = bitcast<u32>(fp.y);
    for (var a = 1u; a <= 3u; a++) {
        let t = polarity_target(a, v, f, s, theta);
        pol_out[o + 2u * a] = bitcast<u32>(t.x);
        pol_out[o + 2u * a + 1u] = bitcast<u32>(t.y);
        pol_out[o + 7u + a] = bitcast<u32>(polarity_rate(w[9], t, theta));
    }
    let words = philox4x32_10(
        vec4<u32>(pol_in[x + 10u], pol_in[x + 11u], pol_in[x + 12u], pol_in[x + 13u]),
        vec2<u32>(pol_in[x + 14u], pol_in[x + 15u]),
    );
    pol_out[o + 11u] = words.x;
    pol_out[o + 12u] = words.y;
    pol_out[o + 13u] = words.z;
    pol_out[o + 14u] = words.w;
    pol_out[o + 15u] = bitcast<u32>(normal_of_words(words.z, words.w));
}

fn function_inputs(x: u32) -> array<f32, 10> {
    var w: array<f32, 10>;
    for (var k = 0u; k < 10u; k++) {
        w[k] = bitcast<f32>(pol_in[x + k]);
    }
    return w;
}
"#;

/// The polarity's WGSL functions (`polarity_force`, `polarity_target`, `polarity_rate`)
/// against `mechanics::terms::{propulsion, alignment_target, alignment_rate}`, and Philox and
/// the normal deviate against the host's, on random inputs: Philox to the bit (the same
/// integer arithmetic), the rest to f32 round-off of their scale. Angles up to ±40 rad (a
/// polarity's angle is not wrapped), forces and velocities of both signs, contact inhibition
/// from none to strong.
#[test]
#[cfg_attr(
    no_vulkan_driver,
    ignore = "no Vulkan driver was installed when the tests were built (apt-get install mesa-vulkan-drivers libvulkan1, then build again)"
)]
fn the_polarity_and_its_noise_match_their_rust_references() {
    use mechanics::terms::{self, Align};
    let Some(device) = common::try_device() else {
        return;
    };
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    let n = 4096;
    let mut input: Vec<u32> = Vec::with_capacity(n * POLARITY_IN);
    for _ in 0..n {
        let floats = [
            rng.random_range(-40.0f32..40.0),
            rng.random_range(-0.05f32..0.05),
            rng.random_range(-0.05f32..0.05),
            rng.random_range(-0.05f32..0.05),
            rng.random_range(-0.05f32..0.05),
            rng.random_range(-0.3f32..0.3),
            rng.random_range(-0.3f32..0.3),
            rng.random_range(-0.1f32..0.1),
            if rng.random_bool(0.25) {
                0.0
            } else {
                rng.random_range(0.0f32..3.0)
            },
            rng.random_range(0.0f32..2.0),
        ];
        input.extend(floats.iter().map(|v| v.to_bits()));
        input.extend((0..6).map(|_| rng.random::<u32>()));
    }
    let shape = PatchShape::new(Lattice::new(64, 64), 8).unwrap();
    let source = gpu::shader_source(&shape, PressureKind::Paper, 32) + POLARITY_HARNESS;
    let out = run_harness(
        &device,
        &source,
        "polarity_equations",
        None,
        bytemuck::cast_slice(&input),
        n * POLARITY_OUT,
    );
    let mut worst = [0.0f64; 5];
    for (x, o) in input
        .chunks_exact(POLARITY_IN)
        .zip(out.chunks_exact(POLARITY_OUT))
    {
        let w: Vec<f64> = x[..10]
            .iter()
            .map(|&b| f64::from(f32::from_bits(b)))
            .collect();
        let got = |k: usize| f64::from(f32::from_bits(o[k]));
        let (theta, f, v, s) = (w[0], [w[1], w[2]], [w[3], w[4]], [w[5], w[6]]);
        // f32 round-off of a quantity of scale `scale`, after a few operations and the
        // reduction of an angle of up to 40 rad (ε·40 in the angle).
        let check = |what: &str, k: usize, want: f64, scale: f64, worst: &mut f64| {
            let bound = 64.0 * f64::from(f32::EPSILON) * scale;
            let err = (got(k) - want).abs();
            *worst = worst.max(err / scale.max(f64::MIN_POSITIVE));
            assert!(
                err <= bound,
                "{what}: {} on the GPU, {want:e} in Rust ({err:.2e} > {bound:.2e}; inputs {w:?})",
                got(k)
            );
        };
        // The angle is reduced to [−π, π] in f32 first: an error of ε |θ| in the direction,
        // which contact inhibition's exponent `η max(0, −f·p)/|m|` amplifies by its slope.
        let reduced = 1.0 + theta.abs() / std::f64::consts::PI;
        let fp = terms::propulsion(w[7], w[8], f, theta);
        let exponent = 1.0 + w[8] * f[0].hypot(f[1]) / w[7].abs().max(f64::MIN_POSITIVE);
        for (k, want) in fp.into_iter().enumerate() {
            let scale = w[7].abs() * reduced * exponent;
            check("polarity_force", k, want, scale, &mut worst[0]);
        }
        for (a, align) in [Align::Velocity, Align::Force, Align::Shape]
            .into_iter()
            .enumerate()
        {
            let t = terms::alignment_target(align, v, f, s, theta);
            let scale = t[0].hypot(t[1]);
            // Near a shape's degenerate axis (S ≈ 0) or a polarity at right angles to the
            // axis (the end chosen by a sign) the target is ill-conditioned: skipped there.
            let ambiguous = align == Align::Shape && {
                let (sin, cos) = (0.5 * s[1].atan2(s[0])).sin_cos();
                (cos * theta.cos() + sin * theta.sin()).abs() < 1e-3
            };
            if ambiguous {
                continue;
            }
            for c in 0..2 {
                check(
                    "polarity_target",
                    2 + 2 * a + c,
                    t[c],
                    scale * reduced,
                    &mut worst[1],
                );
            }
            let rate = terms::alignment_rate(w[9], t, theta);
            check(
                "polarity_rate",
                8 + a,
                rate,
                w[9] * scale * 4.0,
                &mut worst[2],
            );
        }
        let mut counter = [0u32; 4];
        counter.copy_from_slice(&x[10..14]);
        let words = terms::philox4x32_10(counter, [x[14], x[15]]);
        assert_eq!(&o[11..15], &words, "philox4x32_10 of {counter:x?}");
        let normal = terms::normal_of_words(words[2], words[3]);
        // The deviate's round-off: f32's in ln u₁ (relative, `minus_log_uniform`) and in the
        // cosine's argument (absolute, about 2π ε).
        let bound = 64.0 * f64::from(f32::EPSILON) * (1.0 + normal.abs());
        let err = (got(15) - normal).abs();
        worst[3] = worst[3].max(err);
        assert!(
            err <= bound,
            "normal_of_words: {} on the GPU, {normal} in Rust",
            got(15)
        );
    }
    for (name, w) in [
        "polarity_force",
        "polarity_target",
        "polarity_rate",
        "normal_of_words (absolute)",
    ]
    .iter()
    .zip(worst)
    {
        println!("{name}: worst error {w:.2e} of its scale");
    }
}
