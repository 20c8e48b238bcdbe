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


// One step done: counted unless the check stopped the run.
@compute @workgroup_size(1)
fn count_step() {
    if (!halted()) {
        atomicAdd(&status.steps, 1u);
    }
}
