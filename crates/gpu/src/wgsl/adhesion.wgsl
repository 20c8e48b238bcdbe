// Adhesion (ω ≠ 0): the lattice pass adds each cell's `c φ ∇²φ` to the pressure's own part
// and keeps s1 per node (`adh_s1`); the adhesion pass takes the lattice Laplacian of s1
// (`adh_lap`) and adds the cross part `−c s1 ∇²s1` to P; the force pass adds the derivative
// `−c (∇²s1 − ∇²φ_i)`.
override ADHESION: u32 = 0u;

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

