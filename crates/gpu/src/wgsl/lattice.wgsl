// ---- pass 2: the lattice sums and the pressure, gathered node by node ----

@compute @workgroup_size(256)
fn lattice_sums(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let node = gid.x + gid.y * nwg.x * WG;
    if (node >= prm.lx * prm.ly || halted()) {
        return;
    }
    let x = node / prm.ly;
    let y = node % prm.ly;
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

