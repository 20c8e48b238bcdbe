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
    var v = vec2<f32>(0.0);
    if (chunk.first == 0u) {
        v = lat_get(node).xy;
    }
    let hi = chunk.lo + chunk.count;
    for (var cb = 0u; cb < covering_count(); cb++) {
        let b = covering_bin(x, y, cb);
        let n = min(atomicLoad(&bin_count[b]), CAP);
        for (var j = 0u; j < n; j++) {
            let i = bin_cells[b * CAP + j];
            if (i < chunk.lo || i >= hi) {
                continue;
            }
            let ab = patch_node(i, x, y);
            let a = ab.x;
            let bb = ab.y;
            if (a < NX && bb < NY) {
                let p = x_phi[(i - chunk.lo) * PLEN + a * NY + bb];
                let c = i * CELL_STRIDE;
                v += p * vec2<f32>(cell[c + 7u], cell[c + 8u]);
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
