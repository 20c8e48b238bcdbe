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

