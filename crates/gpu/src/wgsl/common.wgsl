// The declarations every stage shares: the status, the lattice arrays' accessors, the
// workgroup scratch, the population constants of the cell at hand, the stencil and the
// helpers. The kernels of the paper's time step (docs/model.md §2–5) are in one file per
// stage (cells, bins, lattice, force, observe) and one per feature (walls, adhesion,
// polarity, growth); the host joins them into one module (`shader.rs`).
//
// The host prepends the constants NX, NY, PLEN (= NX * NY), NPT (nodes per invocation,
// ceil(PLEN / WG)), MARGIN, CAP (cells per bin), PAPER (1 for the paper pressure form,
// 0 for the interaction form), LAT_SPLIT (the lattice nodes in the first binding of each
// lattice array), MAX_KINDS, LOCAL_PATCH and LOCAL_LEN; the structures `Params`, `Kind` and
// `Chunk` (generated from their Rust definitions, `shared_struct!` in shared.rs, so that the
// two layouts cannot drift); and every buffer's `@group(0) @binding(k)` declaration, generated
// from one table (`bindings.rs`) that also gives the layouts, so that each pipeline binds only
// the buffers its entry point uses.
//
// Every equation is one function with the name of its Rust reference in
// `mechanics::equations` or `phasefield::EnergyCoefficients`; the tests check each against it.
// Arithmetic is f32. Every sum has a fixed order: per-cell sums are a tree over the
// workgroup's fixed partial sums, lattice sums add the covering cells bin by bin in a fixed
// bin order and, inside a bin, in increasing slot order. No float atomics anywhere.

const WG: u32 = 256u;
const TAU: f32 = 6.283185307179586;

struct Status {
    failed: atomic<u32>,
    overflow: atomic<u32>,
    steps: atomic<u32>,
    cell: atomic<u32>,
}

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

const CELL_STRIDE: u32 = 12u;

// The constants of each population (`kinds`, one entry, the tissue's, without populations),
// and those of the cell at hand, which the equations read: set by `use_cell` from the
// population index the host writes into the cell's slot 11.
var<private> kc: Kind;

fn use_cell(c: u32) {
    kc = kinds[bitcast<u32>(cell[c + 11u])];
    // A growing cell (growth.wgsl): its target area scaled by the growth factor.
    if (GROWTH == 1u) {
        let g = growth_factor(c);
        kc.area /= g;
        kc.inv_target_area /= g;
    }
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

// ---- the cells that may cover a lattice node (the lattice and observables passes) ----

// How many bins hold the origins of the patches that may cover a node: the node's bin and the
// one before it in each direction (a bin is at least a patch wide), fewer on a lattice of one
// bin along a direction.
fn covering_count() -> u32 {
    return min(prm.nbx, 2u) * min(prm.nby, 2u);
}

// The `q`-th of those bins for node (x, y), in the fixed order the sums add them: the −x
// offset outer, the −y offset inner.
fn covering_bin(x: u32, y: u32, q: u32) -> u32 {
    let ny_b = min(prm.nby, 2u);
    let bx = x * prm.nbx / prm.lx;
    let by = y * prm.nby / prm.ly;
    let cx = (bx + prm.nbx - q / ny_b) % prm.nbx;
    let cy = (by + prm.nby - q % ny_b) % prm.nby;
    return cx * prm.nby + cy;
}

// The node (a, b) of cell `i`'s patch at lattice node (x, y); outside the patch (a ≥ NX or
// b ≥ NY) where the patch does not cover the node.
fn patch_node(i: u32, x: u32, y: u32) -> vec2<u32> {
    let o = origin[i];
    return vec2<u32>((x + prm.lx - o.x) % prm.lx, (y + prm.ly - o.y) % prm.ly);
}
