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

