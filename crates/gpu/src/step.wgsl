// The paper's time step (docs/model.md §2–5) as WGSL compute kernels: one workgroup per cell
// for the per-cell passes, one invocation per lattice node for the lattice sums.
//
// The host prepends the constants NX, NY, PLEN (= NX * NY), NPT (nodes per invocation,
// ceil(PLEN / WG)), MARGIN, CAP (cells per bin), PAPER (1 for the paper pressure form,
// 0 for the interaction form) and LAT_SPLIT (the lattice nodes in the first binding of each
// lattice array).
//
// Every equation is one function below with the name of its Rust reference in
// `mechanics::equations` or `phasefield::EnergyCoefficients`; the tests check each against it.
// Arithmetic is f32. Every sum has a fixed order: per-cell sums are a tree over the
// workgroup's fixed partial sums, lattice sums add the covering cells bin by bin in a fixed
// bin order and, inside a bin, in increasing slot order. No float atomics anywhere.

const WG: u32 = 256u;
const TAU: f32 = 6.283185307179586;

// `Params` and `Chunk` are prepended by the host, generated from their Rust definitions
// (`shared_struct!` in step.rs), so that the two layouts cannot drift.

struct Status {
    failed: atomic<u32>,
    overflow: atomic<u32>,
    steps: atomic<u32>,
    cell: atomic<u32>,
}

@group(0) @binding(0) var<uniform> prm: Params;
// The state evaluated (φ in the passes' sense): read only.
@group(0) @binding(1) var<storage, read> x_phi: array<f32>;
// φ_old of the step (the correctors read it; the last writes the new state there).
@group(0) @binding(2) var<storage, read_write> old_phi: array<f32>;
// R(φ) of the first evaluation.
@group(0) @binding(3) var<storage, read_write> k1: array<f32>;
// The predictor's or a middle corrector's output.
@group(0) @binding(4) var<storage, read_write> out_phi: array<f32>;
// Per cell, 12 floats: area, S_xx, S_xy, φ_min, φ_max, F_x, F_y, v_x, v_y, centre x, y, and
// the population index (a u32's bits, written by the host).
@group(0) @binding(5) var<storage, read_write> cell: array<f32>;
// Per cell: the lattice origin of its patch (x, y).
@group(0) @binding(6) var<storage, read_write> origin: array<vec2<u32>>;
// Per node (x * ly + y): P, s2, Q_xx, Q_xy.
// Split at node LAT_SPLIT into two bindings (lat, then lat_hi), so that a lattice of more
// than 2³¹ bytes (1.3·10⁸ nodes) fits: read and written through lat_get and lat_set.
@group(0) @binding(7) var<storage, read_write> lat: array<vec4<f32>>;
@group(0) @binding(14) var<storage, read_write> lat_hi: array<vec4<f32>>;
// Per bin: the number of cells whose origin lies in it.
@group(0) @binding(8) var<storage, read_write> bin_count: array<atomic<u32>>;
// Per bin: CAP slots of cell indices, sorted.
@group(0) @binding(9) var<storage, read_write> bin_cells: array<u32>;
// cos, sin of 2π x/lx (lx of each), then of 2π y/ly (ly of each).
@group(0) @binding(10) var<storage, read> trig: array<vec2<f32>>;
@group(0) @binding(11) var<storage, read_write> status: Status;
@group(0) @binding(12) var<uniform> chunk: Chunk;
// Per node, with more than one chunk: the partial sums of the chunks before this one,
// s1, s2, s3, s4 in acc_a and own, Q_xx, Q_xy (and one unused) in acc_b, each split at
// LAT_SPLIT as `lat` is.
@group(0) @binding(13) var<storage, read_write> acc_a: array<vec4<f32>>;
@group(0) @binding(15) var<storage, read_write> acc_a_hi: array<vec4<f32>>;
@group(0) @binding(16) var<storage, read_write> acc_b: array<vec4<f32>>;
@group(0) @binding(17) var<storage, read_write> acc_b_hi: array<vec4<f32>>;

fn lat_get(node: u32) -> vec4<f32> {
    if (node < LAT_SPLIT) {
        return lat[node];
    }
    return lat_hi[node - LAT_SPLIT];
}

fn lat_set(node: u32, v: vec4<f32>) {
    if (node < LAT_SPLIT) {
        lat[node] = v;
    } else {
        lat_hi[node - LAT_SPLIT] = v;
    }
}

fn acc_get(node: u32) -> array<vec4<f32>, 2> {
    if (node < LAT_SPLIT) {
        return array<vec4<f32>, 2>(acc_a[node], acc_b[node]);
    }
    let k = node - LAT_SPLIT;
    return array<vec4<f32>, 2>(acc_a_hi[k], acc_b_hi[k]);
}

fn acc_set(node: u32, a: vec4<f32>, b: vec4<f32>) {
    if (node < LAT_SPLIT) {
        acc_a[node] = a;
        acc_b[node] = b;
    } else {
        let k = node - LAT_SPLIT;
        acc_a_hi[k] = a;
        acc_b_hi[k] = b;
    }
}

var<workgroup> red: array<vec4<f32>, WG>;
var<workgroup> shared_v: vec4<f32>;
var<workgroup> shared_shift: vec2<i32>;
var<workgroup> wg_halt: u32;

// Which update the force pass ends with: 0 the predictor (k1 and φ*), 1 a middle corrector,
// 2 the last corrector with the centres and the re-centred patches.
override MODE: u32 = 0u;
// Whether the cell pass checks the state (the first evaluation of a step).
override CHECK: u32 = 0u;
// Whether the tissue has walls: the lattice pass adds their pressure and the force pass their
// derivative, from the static wall field (w, ∇²w per node, `wall`).
override WALLS: u32 = 0u;
@group(0) @binding(19) var<storage, read> wall: array<vec2<f32>>;
// Whether the cells adhere (ω ≠ 0): the lattice pass adds each cell's `c φ ∇²φ` to the
// pressure's own part and keeps s1 per node (`adh_s1`); the adhesion pass takes the lattice
// Laplacian of s1 (`adh_lap`) and adds the cross part `−c s1 ∇²s1` to P; the force pass adds
// the derivative `−c (∇²s1 − ∇²φ_i)`.
override ADHESION: u32 = 0u;
@group(0) @binding(20) var<storage, read_write> adh_s1: array<f32>;
@group(0) @binding(21) var<storage, read_write> adh_lap: array<f32>;
// Whether cells grow before they divide (the division clock's growth phase): per slot, the
// time its target area starts to grow, less the growth's origin (`Params::growth_now`).
override GROWTH: u32 = 0u;
@group(0) @binding(24) var<storage, read> growth: array<f32>;
// Per workgroup of the lattice: Σ |v|² of the tissue velocity over its nodes (`velocity_reduce`).
@group(0) @binding(22) var<storage, read_write> v2_part: array<f32>;

const CELL_STRIDE: u32 = 12u;

// Whether the cells are self-propelled along a polarity (docs/model.md §11.1): the force pass
// adds each cell's propulsion to its interface force before the velocity, and
// `polarity_update` steps each cell's angle by Heun's method after each evaluation of a step,
// with the noise drawn by Philox from the same key as the host's (`mechanics::terms::NoiseKey`).
override POLARITY: u32 = 0u;
// Per cell, POL_STRIDE floats: θ, θ at the step's start, the rate there (or the stiffness
// that stopped the step, for the host's message), the noise kick b·N, what the last evaluation
// of a step computed for the cell (its area and interface force: the propulsion's inputs, as
// the host's `Terms` keeps them by identity, so that an observation's evaluation between
// steps changes nothing), and the cell's identity (a u32's bits).
@group(0) @binding(23) var<storage, read_write> pol: array<f32>;
const POL_STRIDE: u32 = 8u;

// The constants of each population (`Kind`, generated from its Rust definition; one entry, the
// tissue's, without populations), and those of the cell at hand, which the equations read:
// set by `use_cell` from the population index the host writes into the cell's slot 11.
@group(0) @binding(18) var<uniform> kinds: array<Kind, MAX_KINDS>;
var<private> kc: Kind;

fn use_cell(c: u32) {
    kc = kinds[bitcast<u32>(cell[c + 11u])];
    // A growing cell (the division clock's growth phase, mechanics::division): its target
    // area scaled by 1 + clamp((t − t_g0)/T_g, 0, 1) at the time t of the step's start, as the
    // host's `target_scale`.
    if (GROWTH == 1u) {
        let now = prm.growth_now + f32(atomicLoad(&status.steps)) * prm.dt;
        let g = 1.0 + clamp((now - growth[c / CELL_STRIDE]) / prm.growth_time, 0.0, 1.0);
        kc.area /= g;
        kc.inv_target_area /= g;
    }
}

// ---- the equations ----

// phasefield::EnergyCoefficients::area_factor
fn area_factor(area: f32) -> f32 {
    return -kc.area * (1.0 - area * kc.inv_target_area);
}

// phasefield::EnergyCoefficients::free_energy_derivative
fn free_energy_derivative(phi: f32, lap: f32, af: f32, others_sq: f32) -> f32 {
    let ch = kc.double_well * phi * (1.0 - phi) * (1.0 - 2.0 * phi) - kc.gradient * lap;
    return ch + af * phi + prm.repulsion * phi * others_sq;
}

// mechanics::equations::shape_tensor_density
fn shape_tensor_density(grad: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(0.5 * (grad.y * grad.y - grad.x * grad.x), -(grad.x * grad.y));
}

// mechanics::equations::pressure_cell_part
fn pressure_cell_part(phi: f32, lap: f32, af: f32) -> f32 {
    if (PAPER == 1u) {
        return -prm.repulsion * (phi * phi) * phi
            - kc.double_well * phi * (1.0 - phi) * (1.0 - 2.0 * phi)
            + kc.gradient * lap - af * phi;
    }
    return -prm.repulsion * (phi * phi) * (phi * phi);
}

// mechanics::equations::pressure
fn pressure(s1: f32, s2: f32, u: f32) -> f32 {
    if (PAPER == 1u) {
        return prm.repulsion * s1 * s2 + u;
    }
    return prm.repulsion * s2 * s2 + u;
}

// The same pressure regrouped for f32: the repulsion's cross term from the sums,
// (2κ/λ)(s1 s2 − s3) (paper) or (2κ/λ)(s2² − s4) (interaction), which is exactly zero where one
// cell is alone, and `own = Σ_i pressure_own_part`. In f32 the form of `pressure`, whose two
// repulsion terms cancel where one cell is alone, is off by about 1e-6 of the largest P.
fn pressure_regrouped(s1: f32, s2: f32, s3: f32, s4: f32, own: f32) -> f32 {
    if (PAPER == 1u) {
        return prm.repulsion * (s1 * s2 - s3) + own;
    }
    return prm.repulsion * (s2 * s2 - s4) + own;
}

// `pressure_cell_part` less its repulsion term −(2κ/λ)φ³ (paper) or −(2κ/λ)φ⁴ (interaction).
fn pressure_own_part(phi: f32, lap: f32, af: f32) -> f32 {
    if (PAPER == 1u) {
        return -kc.double_well * phi * (1.0 - phi) * (1.0 - 2.0 * phi)
            + kc.gradient * lap - af * phi;
    }
    return 0.0;
}

// mechanics::equations::pressure_self_part
fn pressure_self_part(phi: f32) -> f32 {
    if (PAPER == 1u) {
        return -(kc.double_well * phi * (1.0 - phi) * (1.0 - 2.0 * phi));
    }
    return 0.0;
}

// mechanics::equations::force_density
fn force_density(p_cell: f32, zeta: f32, q: vec2<f32>, grad: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(
        p_cell * grad.x + zeta * (q.x * grad.x + q.y * grad.y),
        p_cell * grad.y + zeta * (q.y * grad.x - q.x * grad.y),
    );
}

// mechanics::equations::velocity
fn velocity(force: vec2<f32>, xi: f32) -> vec2<f32> {
    return force / xi;
}

// mechanics::equations::rhs
fn rhs(v: vec2<f32>, grad: vec2<f32>, dfdphi: f32) -> f32 {
    return -v.x * grad.x - v.y * grad.y - dfdphi;
}

// mechanics::equations::wall_derivative, with the coefficients of `prm`
fn wall_derivative(phi: f32, w: f32, lap_w: f32) -> f32 {
    return prm.wall_repulsion * phi * (w * w) - prm.wall_adhesion * lap_w;
}

// mechanics::equations::wall_pressure, with the coefficients of `prm`
fn wall_pressure(s1: f32, s2: f32, w: f32, lap_w: f32) -> f32 {
    return prm.wall_repulsion * (w * w) * s2 - prm.wall_adhesion * lap_w * s1;
}

// mechanics::equations::adhesion_derivative, with c = prm.adhesion
fn adhesion_derivative(lap_s1: f32, lap_self: f32) -> f32 {
    return -prm.adhesion * (lap_s1 - lap_self);
}

// mechanics::equations::adhesion_pressure_cell_part, with c = prm.adhesion
fn adhesion_pressure_cell_part(phi: f32, lap: f32) -> f32 {
    return prm.adhesion * phi * lap;
}

// mechanics::equations::adhesion_pressure, with c = prm.adhesion
fn adhesion_pressure(s1: f32, lap_s1: f32) -> f32 {
    return -prm.adhesion * s1 * lap_s1;
}

// mechanics::equations::heun_predictor
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

fn heun_predictor(phi_old: f32, dt: f32, r_old: f32) -> f32 {
    return phi_old + dt * r_old;
}

// mechanics::equations::heun_corrector
fn heun_corrector(phi_old: f32, dt: f32, r_old: f32, r_new: f32) -> f32 {
    return phi_old + 0.5 * dt * (r_old + r_new);
}

// ---- the stencil on a cell's periodic patch (logical order, index a * NY + b) ----

struct Stencil {
    c: f32,
    xm: f32,
    xp: f32,
    ym: f32,
    yp: f32,
}

// The patch indices of the stencil at node (a, b) of a patch, periodic within the patch: the
// centre, then −x, +x, −y, +y.
fn stencil_nodes(a: u32, b: u32) -> array<u32, 5> {
    let am = select(a - 1u, NX - 1u, a == 0u);
    let ap = select(a + 1u, 0u, a + 1u == NX);
    let bm = select(b - 1u, NY - 1u, b == 0u);
    let bp = select(b + 1u, 0u, b + 1u == NY);
    return array<u32, 5>(a * NY + b, am * NY + b, ap * NY + b, a * NY + bm, a * NY + bp);
}

fn stencil(base: u32, a: u32, b: u32) -> Stencil {
    let k = stencil_nodes(a, b);
    var s: Stencil;
    s.c = x_phi[base + k[0]];
    s.xm = x_phi[base + k[1]];
    s.xp = x_phi[base + k[2]];
    s.ym = x_phi[base + k[3]];
    s.yp = x_phi[base + k[4]];
    return s;
}

// The variant with each cell's patch in workgroup memory (`Variant::SharedPatch`): the cell and
// force passes load the cell's patch once (`load_patch`), and their stencils read it there
// (`cell_stencil`) instead of five times from the φ array. The host sets LOCAL_PATCH (0 or 1)
// and LOCAL_LEN (PLEN, or 1 for the plain variant, which then holds no patch).
var<workgroup> wg_patch: array<f32, LOCAL_LEN>;

// Loads the patch at `base` of `x_phi` into `wg_patch` (every invocation of the workgroup).
fn load_patch(base: u32, lid: u32) {
    if (LOCAL_PATCH == 1u) {
        for (var k = lid; k < PLEN; k += WG) {
            wg_patch[k] = x_phi[base + k];
        }
        workgroupBarrier();
    }
}

// `stencil` of the workgroup's own cell: from `wg_patch` in the shared-patch variant, the
// same values.
fn cell_stencil(base: u32, a: u32, b: u32) -> Stencil {
    if (LOCAL_PATCH == 0u) {
        return stencil(base, a, b);
    }
    let k = stencil_nodes(a, b);
    var s: Stencil;
    s.c = wg_patch[k[0]];
    s.xm = wg_patch[k[1]];
    s.xp = wg_patch[k[2]];
    s.ym = wg_patch[k[3]];
    s.yp = wg_patch[k[4]];
    return s;
}

// The five-point Laplacian as a sum of differences, each exact in f32 where the neighbours are
// within a factor 2 of the centre (Sterbenz): its rounding error is that of a small result,
// where `xm + xp + ym + yp − 4c` loses the digits of values near 1.
fn laplacian(s: Stencil) -> f32 {
    return ((s.xm - s.c) + (s.xp - s.c)) + ((s.ym - s.c) + (s.yp - s.c));
}

fn gradient(s: Stencil) -> vec2<f32> {
    return 0.5 * vec2<f32>(s.xp - s.xm, s.yp - s.ym);
}

// ---- helpers ----

fn cell_index(wid: vec3<u32>) -> u32 {
    return wid.x + wid.y * prm.grid_x;
}

fn halted() -> bool {
    return atomicLoad(&status.failed) != 0u;
}

// `halted`, the same for every invocation of a workgroup (so that barriers stay uniform).
fn halted_uniform(lid: u32) -> bool {
    if (lid == 0u) {
        wg_halt = select(0u, 1u, halted());
    }
    return workgroupUniformLoad(&wg_halt) != 0u;
}

// A fixed tree over the workgroup's partial sums: the same order on every run.
fn reduce(lid: u32, v: vec4<f32>) -> vec4<f32> {
    red[lid] = v;
    workgroupBarrier();
    var s = WG / 2u;
    loop {
        if (s == 0u) {
            break;
        }
        if (lid < s) {
            red[lid] = red[lid] + red[lid + s];
        }
        workgroupBarrier();
        s = s / 2u;
    }
    let r = red[0];
    workgroupBarrier();
    return r;
}

fn bin_of(o: vec2<u32>) -> u32 {
    let bx = o.x * prm.nbx / prm.lx;
    let by = o.y * prm.nby / prm.ly;
    return bx * prm.nby + by;
}

// ---- pass 1: per cell, area, deformation tensor, range, and the check ----

@compute @workgroup_size(256)
fn cell_sums(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_id) lid3: vec3<u32>) {
    let li = cell_index(wid);
    let lid = lid3.x;
    if (li >= chunk.count || halted_uniform(lid)) {
        return;
    }
    let i = chunk.lo + li;
    let base = li * PLEN;
    load_patch(base, lid);
    var acc = vec4<f32>(0.0);
    var lo = 3.0e38;
    var hi = -3.0e38;
    var bad = false;
    for (var k = lid; k < PLEN; k += WG) {
        let a = k / NY;
        let b = k % NY;
        let s = cell_stencil(base, a, b);
        let sh = shape_tensor_density(gradient(s));
        acc += vec4<f32>(s.c * s.c, sh.x, sh.y, 0.0);
        lo = min(lo, s.c);
        hi = max(hi, s.c);
        // NaN and ±∞ fail this test.
        if (!(abs(s.c) <= 3.0e38)) {
            bad = true;
        }
    }
    let total = reduce(lid, acc);
    // The range: a second tree, with max in the place of +.
    red[lid] = vec4<f32>(-lo, hi, select(0.0, 1.0, bad), 0.0);
    workgroupBarrier();
    var s = WG / 2u;
    loop {
        if (s == 0u) {
            break;
        }
        if (lid < s) {
            red[lid] = max(red[lid], red[lid + s]);
        }
        workgroupBarrier();
        s = s / 2u;
    }
    if (lid == 0u) {
        let m = red[0];
        let c = i * CELL_STRIDE;
        cell[c + 0u] = total.x;
        cell[c + 1u] = total.y;
        cell[c + 2u] = total.z;
        cell[c + 3u] = -m.x;
        cell[c + 4u] = m.y;
        if (CHECK == 1u) {
            let finite = m.z == 0.0 && abs(total.x) <= 3.0e38;
            if (!finite || -m.x < -prm.bound || m.y > 1.0 + prm.bound) {
                if (atomicMax(&status.failed, select(2u, 1u, finite)) == 0u) {
                    atomicStore(&status.cell, i);
                }
            }
        }
    }
}

// ---- bins of patch origins, for the gather ----

@compute @workgroup_size(256)
fn bin_clear(@builtin(global_invocation_id) gid: vec3<u32>) {
    let b = gid.x;
    if (b < prm.nbx * prm.nby) {
        atomicStore(&bin_count[b], 0u);
    }
}

@compute @workgroup_size(256)
fn bin_fill(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= prm.n_cells || halted()) {
        return;
    }
    let b = bin_of(origin[i]);
    let slot = atomicAdd(&bin_count[b], 1u);
    if (slot < CAP) {
        bin_cells[b * CAP + slot] = i;
    } else {
        atomicMax(&status.overflow, 1u);
    }
}

// The slots were taken in whatever order the invocations ran: sort each bin's cells, so that
// the sums add them in increasing index order.
@compute @workgroup_size(256)
fn bin_sort(@builtin(global_invocation_id) gid: vec3<u32>) {
    let b = gid.x;
    if (b >= prm.nbx * prm.nby || halted()) {
        return;
    }
    let n = min(atomicLoad(&bin_count[b]), CAP);
    let o = b * CAP;
    for (var j = 1u; j < n; j++) {
        let v = bin_cells[o + j];
        var k = j;
        loop {
            if (k == 0u || bin_cells[o + k - 1u] <= v) {
                break;
            }
            bin_cells[o + k] = bin_cells[o + k - 1u];
            k -= 1u;
        }
        bin_cells[o + k] = v;
    }
}

// ---- pass 2: the lattice sums and the pressure, gathered node by node ----

@compute @workgroup_size(256)
fn lattice_sums(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let node = gid.x + gid.y * nwg.x * WG;
    if (node >= prm.lx * prm.ly || halted()) {
        return;
    }
    let x = node / prm.ly;
    let y = node % prm.ly;
    let bx = x * prm.nbx / prm.lx;
    let by = y * prm.nby / prm.ly;
    let nx_b = min(prm.nbx, 2u);
    let ny_b = min(prm.nby, 2u);
    var s1 = 0.0;
    var s2 = 0.0;
    var s3 = 0.0;
    var s4 = 0.0;
    var own = 0.0;
    var q = vec2<f32>(0.0);
    if (chunk.first == 0u) {
        let ab = acc_get(node);
        let a0 = ab[0];
        let a1 = ab[1];
        s1 = a0.x;
        s2 = a0.y;
        s3 = a0.z;
        s4 = a0.w;
        own = a1.x;
        q = a1.yz;
    }
    let hi = chunk.lo + chunk.count;
    for (var dx = 0u; dx < nx_b; dx++) {
        let cx = (bx + prm.nbx - dx) % prm.nbx;
        for (var dy = 0u; dy < ny_b; dy++) {
            let cy = (by + prm.nby - dy) % prm.nby;
            let b = cx * prm.nby + cy;
            let n = min(atomicLoad(&bin_count[b]), CAP);
            for (var j = 0u; j < n; j++) {
                let i = bin_cells[b * CAP + j];
                if (i < chunk.lo || i >= hi) {
                    continue;
                }
                let o = origin[i];
                let a = (x + prm.lx - o.x) % prm.lx;
                let bb = (y + prm.ly - o.y) % prm.ly;
                if (a < NX && bb < NY) {
                    let st = stencil((i - chunk.lo) * PLEN, a, bb);
                    let c = i * CELL_STRIDE;
                    use_cell(c);
                    let af = area_factor(cell[c]);
                    let sh = vec2<f32>(cell[c + 1u], cell[c + 2u]);
                    let p = st.c;
                    let p2 = p * p;
                    s1 += p;
                    s2 += p2;
                    s3 += p2 * p;
                    s4 += p2 * p2;
                    let lap = laplacian(st);
                    own += pressure_own_part(p, lap, af);
                    if (ADHESION == 1u) {
                        own += adhesion_pressure_cell_part(p, lap);
                    }
                    q += p * sh * kc.zeta_weight;
                }
            }
        }
    }
    if (chunk.last == 1u) {
        var p = pressure_regrouped(s1, s2, s3, s4, own);
        if (WALLS == 1u) {
            let wl = wall[node];
            p += wall_pressure(s1, s2, wl.x, wl.y);
        }
        if (ADHESION == 1u) {
            adh_s1[node] = s1;
        }
        lat_set(node, vec4<f32>(p, s2, q.x, q.y));
    } else {
        acc_set(node, vec4<f32>(s1, s2, s3, s4), vec4<f32>(own, q.x, q.y, 0.0));
    }
}

// ---- pass 2b, with adhesion: the Laplacian of s1 and the cross part of the pressure ----

@compute @workgroup_size(256)
fn adhesion_lattice(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let node = gid.x + gid.y * nwg.x * WG;
    if (node >= prm.lx * prm.ly || halted()) {
        return;
    }
    let x = node / prm.ly;
    let y = node % prm.ly;
    let xm = select(x - 1u, prm.lx - 1u, x == 0u);
    let xp = select(x + 1u, 0u, x + 1u == prm.lx);
    let ym = select(y - 1u, prm.ly - 1u, y == 0u);
    let yp = select(y + 1u, 0u, y + 1u == prm.ly);
    var s: Stencil;
    s.c = adh_s1[node];
    s.xm = adh_s1[xm * prm.ly + y];
    s.xp = adh_s1[xp * prm.ly + y];
    s.ym = adh_s1[x * prm.ly + ym];
    s.yp = adh_s1[x * prm.ly + yp];
    let lap = laplacian(s);
    adh_lap[node] = lap;
    var l = lat_get(node);
    l.x += adhesion_pressure(s.c, lap);
    lat_set(node, l);
}

// ---- pass 3: forces, velocities, the right-hand side and the Heun update ----

@compute @workgroup_size(256)
fn force_update(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_id) lid3: vec3<u32>) {
    let li = cell_index(wid);
    let lid = lid3.x;
    if (li >= chunk.count || halted_uniform(lid)) {
        return;
    }
    let i = chunk.lo + li;
    let base = li * PLEN;
    load_patch(base, lid);
    let o = origin[i];
    let c = i * CELL_STRIDE;
    use_cell(c);
    var fields: array<vec4<f32>, NPT>;
    var acc = vec4<f32>(0.0);
    for (var j = 0u; j < NPT; j++) {
        let k = lid + j * WG;
        if (k < PLEN) {
            let a = k / NY;
            let b = k % NY;
            let gx = (o.x + a) % prm.lx;
            let gy = (o.y + b) % prm.ly;
            let f = lat_get(gx * prm.ly + gy);
            fields[j] = f;
            let s = cell_stencil(base, a, b);
            let p = f.x - pressure_self_part(s.c);
            let fd = force_density(p, prm.zeta, f.zw, gradient(s));
            acc += vec4<f32>(fd, 0.0, 0.0);
        }
    }
    var fp = vec2<f32>(0.0);
    if (POLARITY == 1u) {
        fp = propulsion_of(i);
    }
    let force = reduce(lid, acc).xy;
    let v = velocity(force + fp, kc.xi);
    let af = area_factor(cell[c]);
    var vals: array<f32, NPT>;
    var four = vec4<f32>(0.0);
    for (var j = 0u; j < NPT; j++) {
        let k = lid + j * WG;
        if (k < PLEN) {
            let a = k / NY;
            let b = k % NY;
            let s = cell_stencil(base, a, b);
            let others = fields[j].y - s.c * s.c;
            let lap = laplacian(s);
            var dfdphi = free_energy_derivative(s.c, lap, af, others);
            let at = ((o.x + a) % prm.lx) * prm.ly + (o.y + b) % prm.ly;
            if (WALLS == 1u) {
                let wl = wall[at];
                dfdphi += wall_derivative(s.c, wl.x, wl.y);
            }
            if (ADHESION == 1u) {
                dfdphi += adhesion_derivative(adh_lap[at], lap);
            }
            let r = rhs(v, gradient(s), dfdphi);
            let idx = base + k;
            if (MODE == 0u) {
                k1[idx] = r;
                out_phi[idx] = heun_predictor(s.c, prm.dt, r);
            } else if (MODE == 1u) {
                out_phi[idx] = heun_corrector(old_phi[idx], prm.dt, k1[idx], r);
            } else {
                let n = heun_corrector(old_phi[idx], prm.dt, k1[idx], r);
                vals[j] = n;
                let gx = (o.x + a) % prm.lx;
                let gy = (o.y + b) % prm.ly;
                let tx = trig[gx];
                let ty = trig[prm.lx + gy];
                four += n * vec4<f32>(tx.x, tx.y, ty.x, ty.y);
            }
        }
    }
    if (lid == 0u) {
        cell[c + 5u] = force.x;
        cell[c + 6u] = force.y;
        cell[c + 7u] = v.x;
        cell[c + 8u] = v.y;
    }
    if (MODE == 2u) {
        // The centre of mass by Fourier phase (phasefield::ComTable::centre_of_mass), then the
        // patch re-centred on it (phasefield::Cells::recentre): every value stays on its node.
        let f = reduce(lid, four);
        if (lid == 0u) {
            let lxf = f32(prm.lx);
            let lyf = f32(prm.ly);
            var cx = atan2(f.y, f.x) / TAU * lxf;
            var cy = atan2(f.w, f.z) / TAU * lyf;
            cx = select(cx, cx + lxf, cx < 0.0);
            cy = select(cy, cy + lyf, cy < 0.0);
            cx = select(cx, cx - lxf, cx >= lxf);
            cy = select(cy, cy - lyf, cy >= lyf);
            cell[c + 9u] = cx;
            cell[c + 10u] = cy;
            let lxi = i32(prm.lx);
            let lyi = i32(prm.ly);
            let nox = ((i32(floor(cx + 0.5)) - i32(MARGIN)) % lxi + lxi) % lxi;
            let noy = ((i32(floor(cy + 0.5)) - i32(MARGIN)) % lyi + lyi) % lyi;
            // The shift by the nearest image.
            var dx = (nox - i32(o.x)) % lxi;
            var dy = (noy - i32(o.y)) % lyi;
            dx = select(dx, dx + lxi, dx < -lxi / 2);
            dx = select(dx, dx - lxi, dx > lxi / 2);
            dy = select(dy, dy + lyi, dy < -lyi / 2);
            dy = select(dy, dy - lyi, dy > lyi / 2);
            shared_shift = vec2<i32>(dx, dy);
            origin[i] = vec2<u32>(u32(nox), u32(noy));
        }
        storageBarrier();
        workgroupBarrier();
        let d = workgroupUniformLoad(&shared_shift);
        let nxi = i32(NX);
        let nyi = i32(NY);
        for (var j = 0u; j < NPT; j++) {
            let k = lid + j * WG;
            if (k < PLEN) {
                let a = i32(k / NY);
                let b = i32(k % NY);
                let na = ((a - d.x) % nxi + nxi) % nxi;
                let nb = ((b - d.y) % nyi + nyi) % nyi;
                old_phi[base + u32(na) * NY + u32(nb)] = vals[j];
            }
        }
    }
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

// ---- observables: the tissue velocity v = Σ_i φ_i v_i and Σ |v|², reduced on the device ----

// Per node, chunk by chunk: v = Σ_i φ_i v_i into P's and s2's places of the lattice sums
// (free once an evaluation's force pass has run), with the cells' velocities of that
// evaluation; the first chunk writes, the others add. The cells in the bins' order, as the
// lattice pass adds them.
@compute @workgroup_size(256)
fn velocity_sums(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let node = gid.x + gid.y * nwg.x * WG;
    if (node >= prm.lx * prm.ly || halted()) {
        return;
    }
    let x = node / prm.ly;
    let y = node % prm.ly;
    let bx = x * prm.nbx / prm.lx;
    let by = y * prm.nby / prm.ly;
    let nx_b = min(prm.nbx, 2u);
    let ny_b = min(prm.nby, 2u);
    var v = vec2<f32>(0.0);
    if (chunk.first == 0u) {
        v = lat_get(node).xy;
    }
    let hi = chunk.lo + chunk.count;
    for (var dx = 0u; dx < nx_b; dx++) {
        let cx = (bx + prm.nbx - dx) % prm.nbx;
        for (var dy = 0u; dy < ny_b; dy++) {
            let cy = (by + prm.nby - dy) % prm.nby;
            let b = cx * prm.nby + cy;
            let n = min(atomicLoad(&bin_count[b]), CAP);
            for (var j = 0u; j < n; j++) {
                let i = bin_cells[b * CAP + j];
                if (i < chunk.lo || i >= hi) {
                    continue;
                }
                let o = origin[i];
                let a = (x + prm.lx - o.x) % prm.lx;
                let bb = (y + prm.ly - o.y) % prm.ly;
                if (a < NX && bb < NY) {
                    let p = x_phi[(i - chunk.lo) * PLEN + a * NY + bb];
                    let c = i * CELL_STRIDE;
                    v += p * vec2<f32>(cell[c + 7u], cell[c + 8u]);
                }
            }
        }
    }
    lat_set(node, vec4<f32>(v, 0.0, 0.0));
}

// Per workgroup of 256 nodes: Σ |v|², a fixed tree (the host adds the workgroups' sums).
@compute @workgroup_size(256)
fn velocity_reduce(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(local_invocation_id) lid3: vec3<u32>,
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
) {
    let node = gid.x + gid.y * nwg.x * WG;
    var v2 = 0.0;
    if (node < prm.lx * prm.ly) {
        let v = lat_get(node).xy;
        v2 = dot(v, v);
    }
    let total = reduce(lid3.x, vec4<f32>(v2, 0.0, 0.0, 0.0));
    if (lid3.x == 0u) {
        v2_part[wid.x + wid.y * nwg.x] = total.x;
    }
}

// One step done: counted unless the check stopped the run.
@compute @workgroup_size(1)
fn count_step() {
    if (!halted()) {
        atomicAdd(&status.steps, 1u);
    }
}
