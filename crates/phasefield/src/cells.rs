//! The phase fields of all cells ([`Cells`]) in structure-of-arrays layout, and where each
//! cell's patch sits on the lattice ([`PatchMap`]): origins, offsets, and moves that keep each
//! value on its lattice node and the patch in logical order.
//!
//! All cells' values are one contiguous `Vec<T>` with stride `patch_len`; within a patch the
//! storage index is `a * ny + b` (x slow, y contiguous, as on the [`Lattice`]).

use crate::lattice::Lattice;
use crate::real::Real;
use crate::shape::PatchShape;

/// Where each cell's patch sits on the lattice: origins, offsets and the storage-to-lattice
/// coordinate tables derived from them.
#[derive(Debug, Clone)]
pub struct PatchMap {
    /// Lattice coordinates of each patch's logical first column and row.
    pub origin: Vec<[usize; 2]>,
    /// Storage indices of each patch's logical first column and row.
    pub offset: Vec<[usize; 2]>,
    /// `lat_x[i * nx + a]`: lattice x of storage column `a` of cell `i`.
    pub lat_x: Vec<u32>,
    /// `lat_y[i * ny + b]`: lattice y of storage row `b` of cell `i`.
    pub lat_y: Vec<u32>,
}

impl PatchMap {
    /// Bytes of heap memory held by the map.
    pub fn heap_bytes(&self) -> usize {
        self.origin.capacity() * std::mem::size_of::<[usize; 2]>()
            + self.offset.capacity() * std::mem::size_of::<[usize; 2]>()
            + (self.lat_x.capacity() + self.lat_y.capacity()) * std::mem::size_of::<u32>()
    }

    /// Lattice x of each storage column of cell `i`.
    #[inline]
    pub fn cell_x<'a>(&'a self, shape: &PatchShape, i: usize) -> &'a [u32] {
        &self.lat_x[i * shape.nx..(i + 1) * shape.nx]
    }
    /// Lattice y of each storage row of cell `i`.
    #[inline]
    pub fn cell_y<'a>(&'a self, shape: &PatchShape, i: usize) -> &'a [u32] {
        &self.lat_y[i * shape.ny..(i + 1) * shape.ny]
    }

    fn refresh_tables(&mut self, lattice: Lattice, shape: &PatchShape, i: usize) {
        let [ox, oy] = self.origin[i];
        let [fx, fy] = self.offset[i];
        let (nx, ny) = (shape.nx, shape.ny);
        for a in 0..nx {
            let u = (a + nx - fx) % nx;
            self.lat_x[i * nx + a] = ((ox + u) % lattice.lx) as u32;
        }
        for b in 0..ny {
            let v = (b + ny - fy) % ny;
            self.lat_y[i * ny + b] = ((oy + v) % lattice.ly) as u32;
        }
    }
}

/// The phase fields of all cells, in structure-of-arrays layout.
#[derive(Debug, Clone)]
pub struct Cells<T: Real = f64> {
    lattice: Lattice,
    shape: PatchShape,
    n_cells: usize,
    phi: Vec<T>,
    map: PatchMap,
}

impl Cells<f64> {
    /// `n_cells` cells with all-zero fields, each patch centred on `centres[i]`.
    ///
    /// # Panics
    /// If `centres.len() != n_cells`.
    pub fn zeros(lattice: Lattice, shape: PatchShape, centres: &[[f64; 2]]) -> Self {
        Self::blank(lattice, shape, centres)
    }
}

impl<T: Real> Cells<T> {
    /// All-zero fields in this precision, each patch centred on `centres[i]`.
    fn blank(lattice: Lattice, shape: PatchShape, centres: &[[f64; 2]]) -> Self {
        let n_cells = centres.len();
        let mut map = PatchMap {
            origin: vec![[0, 0]; n_cells],
            offset: vec![[0, 0]; n_cells],
            lat_x: vec![0; n_cells * shape.nx],
            lat_y: vec![0; n_cells * shape.ny],
        };
        for i in 0..n_cells {
            map.origin[i] = Self::origin_for(lattice, &shape, centres[i]);
            map.refresh_tables(lattice, &shape, i);
        }
        Self {
            lattice,
            phi: vec![T::default(); n_cells * shape.len()],
            shape,
            n_cells,
            map,
        }
    }

    /// Cells from patches in logical order (as written by [`Cells::unrolled_into`]): cell `i`'s
    /// element `u * ny + v` is its value at node `(origins[i] + (u, v)) mod L`.
    ///
    /// # Panics
    /// If `values.len() != origins.len() * shape.len()` or an origin is off the lattice.
    pub fn from_unrolled(
        lattice: Lattice,
        shape: PatchShape,
        origins: &[[usize; 2]],
        values: &[f64],
    ) -> Self {
        let n_cells = origins.len();
        assert_eq!(values.len(), n_cells * shape.len());
        let mut map = PatchMap {
            origin: origins.to_vec(),
            offset: vec![[0, 0]; n_cells],
            lat_x: vec![0; n_cells * shape.nx],
            lat_y: vec![0; n_cells * shape.ny],
        };
        for (i, o) in origins.iter().enumerate() {
            assert!(
                o[0] < lattice.lx && o[1] < lattice.ly,
                "origin {o:?} off the lattice"
            );
            map.refresh_tables(lattice, &shape, i);
        }
        Self {
            lattice,
            phi: values.iter().map(|&v| T::from_f64(v)).collect(),
            shape,
            n_cells,
            map,
        }
    }

    /// Cells exactly as they were stored: the field values in storage order (as
    /// [`Cells::phi`] returns them) with each patch's origin and storage offset (as
    /// [`Cells::map`] holds them). Rebuilds the tables, so a checkpoint restores the cells
    /// bit for bit, including where each patch's data sits in its cyclic storage.
    ///
    /// # Errors
    /// A message naming what does not fit: the length of `phi`, an origin off the lattice or
    /// an offset outside the patch.
    pub fn from_storage(
        lattice: Lattice,
        shape: PatchShape,
        phi: Vec<T>,
        origin: Vec<[usize; 2]>,
        offset: Vec<[usize; 2]>,
    ) -> Result<Self, String> {
        let n_cells = origin.len();
        if offset.len() != n_cells || phi.len() != n_cells * shape.len() {
            return Err(format!(
                "{} values, {} origins and {} offsets for patches of {}×{}",
                phi.len(),
                n_cells,
                offset.len(),
                shape.nx,
                shape.ny
            ));
        }
        for (i, (o, f)) in origin.iter().zip(&offset).enumerate() {
            if o[0] >= lattice.lx || o[1] >= lattice.ly || f[0] >= shape.nx || f[1] >= shape.ny {
                return Err(format!(
                    "patch {i}: origin {o:?} or offset {f:?} out of range"
                ));
            }
        }
        let mut map = PatchMap {
            origin,
            offset,
            lat_x: vec![0; n_cells * shape.nx],
            lat_y: vec![0; n_cells * shape.ny],
        };
        for i in 0..n_cells {
            map.refresh_tables(lattice, &shape, i);
        }
        Ok(Self {
            lattice,
            phi,
            shape,
            n_cells,
            map,
        })
    }

    /// Reorders the cells: slot `j` receives the cell that was in slot `order[j]`. Field values
    /// move through `scratch` (resized to the field length once, then reused), so that a
    /// caller can reorder repeatedly without allocating the large buffer again.
    ///
    /// # Panics
    /// If `order` is not a permutation of `0..n_cells()`.
    pub fn permute(&mut self, order: &[usize], scratch: &mut Vec<T>) {
        let n = self.n_cells;
        assert_eq!(order.len(), n);
        let mut seen = vec![false; n];
        for &o in order {
            assert!(o < n && !seen[o], "order must be a permutation");
            seen[o] = true;
        }
        let plen = self.shape.len();
        scratch.resize(self.phi.len(), T::default());
        for (j, &o) in order.iter().enumerate() {
            scratch[j * plen..(j + 1) * plen].copy_from_slice(&self.phi[o * plen..(o + 1) * plen]);
        }
        std::mem::swap(&mut self.phi, scratch);
        let (nx, ny) = (self.shape.nx, self.shape.ny);
        let m = &self.map;
        let mut map = PatchMap {
            origin: order.iter().map(|&o| m.origin[o]).collect(),
            offset: order.iter().map(|&o| m.offset[o]).collect(),
            lat_x: Vec::with_capacity(m.lat_x.len()),
            lat_y: Vec::with_capacity(m.lat_y.len()),
        };
        for &o in order {
            map.lat_x.extend_from_slice(&m.lat_x[o * nx..(o + 1) * nx]);
            map.lat_y.extend_from_slice(&m.lat_y[o * ny..(o + 1) * ny]);
        }
        self.map = map;
    }

    /// Splits cell `cell_idx` in two along the line through `centre` normal to `direction`
    /// (a unit vector), for a cell division: the cell keeps `φ_a = φ χ` and a new cell, added
    /// in the last slot on the same patch, gets `φ_b = φ − φ_a`, with
    /// `χ = ½ [1 + tanh(d/width)]` and `d` the periodic displacement of each node from
    /// `centre` along `direction`. So `φ_a + φ_b = φ` at every node up to one rounding of the
    /// storage precision, and the new cell lies on the side `−direction`. Returns the new
    /// slot. The field vector grows by one patch (`Vec`'s amortised growth: a run of
    /// divisions reallocates O(log N) times).
    ///
    /// # Panics
    /// If `cell_idx` is out of range or `width` is not positive.
    pub fn split(
        &mut self,
        cell_idx: usize,
        centre: [f64; 2],
        direction: [f64; 2],
        width: f64,
    ) -> usize {
        assert!(cell_idx < self.n_cells, "no cell {cell_idx}");
        assert!(width > 0.0, "the split's width must be positive");
        let plen = self.shape.len();
        let (nx, ny) = (self.shape.nx, self.shape.ny);
        let new = self.n_cells;
        self.phi
            .extend_from_within(cell_idx * plen..(cell_idx + 1) * plen);
        self.map.origin.push(self.map.origin[cell_idx]);
        self.map.offset.push(self.map.offset[cell_idx]);
        self.map
            .lat_x
            .extend_from_within(cell_idx * nx..(cell_idx + 1) * nx);
        self.map
            .lat_y
            .extend_from_within(cell_idx * ny..(cell_idx + 1) * ny);
        self.n_cells += 1;
        let l = self.lattice;
        let (head, tail) = self.phi.split_at_mut(new * plen);
        let a_part = &mut head[cell_idx * plen..(cell_idx + 1) * plen];
        for a in 0..nx {
            let x = self.map.lat_x[cell_idx * nx + a] as f64;
            let dx = crate::min_image(x - centre[0], l.lx as f64);
            for b in 0..ny {
                let y = self.map.lat_y[cell_idx * ny + b] as f64;
                let dy = crate::min_image(y - centre[1], l.ly as f64);
                let chi = 0.5 * (1.0 + ((dx * direction[0] + dy * direction[1]) / width).tanh());
                let k = a * ny + b;
                let mother = a_part[k].to_f64();
                let keep = T::from_f64(mother * chi);
                a_part[k] = keep;
                tail[k] = T::from_f64(mother - keep.to_f64());
            }
        }
        new
    }

    /// Removes cell `cell_idx`, moving the cell of the last slot into its place (the order of
    /// the others is kept); returns the slot the moved cell came from (`None` when the removed
    /// cell was the last). Allocates nothing.
    ///
    /// # Panics
    /// If `cell_idx` is out of range.
    pub fn swap_remove(&mut self, cell_idx: usize) -> Option<usize> {
        assert!(cell_idx < self.n_cells, "no cell {cell_idx}");
        let last = self.n_cells - 1;
        let plen = self.shape.len();
        let (nx, ny) = (self.shape.nx, self.shape.ny);
        if cell_idx != last {
            self.phi
                .copy_within(last * plen..(last + 1) * plen, cell_idx * plen);
            self.map
                .lat_x
                .copy_within(last * nx..(last + 1) * nx, cell_idx * nx);
            self.map
                .lat_y
                .copy_within(last * ny..(last + 1) * ny, cell_idx * ny);
        }
        self.phi.truncate(last * plen);
        self.map.lat_x.truncate(last * nx);
        self.map.lat_y.truncate(last * ny);
        self.map.origin.swap_remove(cell_idx);
        self.map.offset.swap_remove(cell_idx);
        self.n_cells = last;
        (cell_idx != last).then_some(last)
    }

    /// The same fields stored with another patch shape (e.g. the full domain, or another
    /// margin), each new patch centred on `centres[i]`; values outside the old patch are zero,
    /// values outside the new one are dropped. Allocates; meant for set-up and studies.
    ///
    /// # Panics
    /// If `centres.len() != n_cells()` or `shape` was built for another lattice.
    pub fn resampled(&self, shape: PatchShape, centres: &[[f64; 2]]) -> Self {
        assert_eq!(centres.len(), self.n_cells);
        let mut out = Self::blank(self.lattice, shape, centres);
        let (nx, ny) = (out.shape.nx, out.shape.ny);
        for i in 0..self.n_cells {
            for a in 0..nx {
                let x = out.map.lat_x[i * nx + a] as usize;
                for b in 0..ny {
                    let y = out.map.lat_y[i * ny + b] as usize;
                    out.phi[i * nx * ny + a * ny + b] = T::from_f64(self.value_at(i, x, y));
                }
            }
        }
        out
    }

    /// The patch origin that centres the patch on the node nearest to `centre`.
    fn origin_for(lattice: Lattice, shape: &PatchShape, centre: [f64; 2]) -> [usize; 2] {
        match shape.margin {
            None => [0, 0],
            Some(m) => [
                lattice.wrap_x(centre[0].round() as i64 - m as i64),
                lattice.wrap_y(centre[1].round() as i64 - m as i64),
            ],
        }
    }

    /// Moves the patch of cell `cell_idx` so that it is centred on the node nearest to
    /// `centre`, keeping every value on its lattice node; the columns and rows that wrap
    /// around keep the values they had on the far edge (the paper's algorithm).
    /// Returns the shift `[dx, dy]` in nodes. A no-op in full-domain mode.
    ///
    /// The patch's values are then rotated in place into logical order (storage offset
    /// `[0, 0]`, see [`Cells::store_in_logical_order`]), so that a patch column is cut into runs
    /// only where it crosses the lattice's edge. A move is rare (a cell crosses a node every
    /// few tens of steps), so the copy costs far less than the split columns it saves.
    pub fn recentre(&mut self, cell_idx: usize, centre: [f64; 2]) -> [i64; 2] {
        let Some(_) = self.shape.margin else {
            return [0, 0];
        };
        let new = Self::origin_for(self.lattice, &self.shape, centre);
        let old = self.map.origin[cell_idx];
        let d = [
            min_image_int(new[0] as i64 - old[0] as i64, self.lattice.lx as i64),
            min_image_int(new[1] as i64 - old[1] as i64, self.lattice.ly as i64),
        ];
        if d == [0, 0] {
            return d;
        }
        let (nx, ny) = (self.shape.nx as i64, self.shape.ny as i64);
        let off = self.map.offset[cell_idx];
        self.map.offset[cell_idx] = [
            (off[0] as i64 + d[0]).rem_euclid(nx) as usize,
            (off[1] as i64 + d[1]).rem_euclid(ny) as usize,
        ];
        self.map.origin[cell_idx] = new;
        self.store_in_logical_order(cell_idx);
        d
    }

    /// Sets every patch's origin, with its values taken to be in logical order (storage
    /// offset `[0, 0]`): for a state computed elsewhere, whose values the caller then writes
    /// through [`Cells::phi_mut`].
    ///
    /// # Panics
    /// If `origins` has not one origin per cell on the lattice.
    pub fn set_logical_origins(&mut self, origins: &[[usize; 2]]) {
        assert_eq!(origins.len(), self.n_cells, "one origin per cell");
        for (i, &o) in origins.iter().enumerate() {
            assert!(
                o[0] < self.lattice.lx && o[1] < self.lattice.ly,
                "origin {o:?} off the lattice"
            );
            self.map.origin[i] = o;
            self.map.offset[i] = [0, 0];
            self.map.refresh_tables(self.lattice, &self.shape, i);
        }
    }

    /// Rotates the values of cell `cell_idx`'s patch in place so that storage column `a` and
    /// row `b` are the logical ones (storage offset `[0, 0]`), and refreshes its tables. Every
    /// value stays on its lattice node; only where it sits in storage changes. Allocates
    /// nothing.
    pub fn store_in_logical_order(&mut self, cell_idx: usize) {
        let [fx, fy] = self.map.offset[cell_idx];
        let (n, ny) = (self.shape.len(), self.shape.ny);
        let patch = &mut self.phi[cell_idx * n..(cell_idx + 1) * n];
        // Storage column (u + fx) mod nx holds logical column u, so rotating left by fx
        // columns puts logical column u at storage column u; likewise for the rows.
        if fx != 0 {
            patch.rotate_left(fx * ny);
        }
        if fy != 0 {
            for column in patch.chunks_exact_mut(ny) {
                column.rotate_left(fy);
            }
        }
        self.map.offset[cell_idx] = [0, 0];
        self.map.refresh_tables(self.lattice, &self.shape, cell_idx);
    }

    /// The lattice.
    pub fn lattice(&self) -> Lattice {
        self.lattice
    }
    /// The patch shape shared by all cells.
    pub fn shape(&self) -> &PatchShape {
        &self.shape
    }
    /// Number of cells.
    pub fn n_cells(&self) -> usize {
        self.n_cells
    }
    /// Nodes per patch.
    pub fn patch_len(&self) -> usize {
        self.shape.len()
    }
    /// All cells' values, cell after cell.
    pub fn phi(&self) -> &[T] {
        &self.phi
    }
    /// All cells' values, mutably.
    pub fn phi_mut(&mut self) -> &mut [T] {
        &mut self.phi
    }
    /// One cell's patch values in storage order.
    pub fn cell_phi(&self, cell_idx: usize) -> &[T] {
        let n = self.shape.len();
        &self.phi[cell_idx * n..(cell_idx + 1) * n]
    }
    /// Where the patches are.
    pub fn map(&self) -> &PatchMap {
        &self.map
    }
    /// Exchanges the field buffer with `other` (same length), without copying: a time stepper
    /// keeps the old state this way.
    ///
    /// # Panics
    /// If the lengths differ.
    pub fn swap_phi(&mut self, other: &mut Vec<T>) {
        assert_eq!(other.len(), self.phi.len(), "buffers of different lengths");
        std::mem::swap(&mut self.phi, other);
    }
    /// The values (mutable) and the patch map (shared) at once, for kernels that write
    /// fields while reading positions.
    pub fn split_mut(&mut self) -> (&mut [T], &PatchMap, &PatchShape) {
        (&mut self.phi, &self.map, &self.shape)
    }

    /// The value of cell `cell_idx` at lattice node `(x, y)`, zero off its patch.
    pub fn value_at(&self, cell_idx: usize, x: usize, y: usize) -> f64 {
        let (nx, ny) = (self.shape.nx, self.shape.ny);
        let [ox, oy] = self.map.origin[cell_idx];
        let u = (x + self.lattice.lx - ox) % self.lattice.lx;
        let v = (y + self.lattice.ly - oy) % self.lattice.ly;
        if u >= nx || v >= ny {
            return 0.0;
        }
        let [fx, fy] = self.map.offset[cell_idx];
        let a = (u + fx) % nx;
        let b = (v + fy) % ny;
        self.cell_phi(cell_idx)[a * ny + b].to_f64()
    }

    /// The patch of cell `cell_idx` unrolled into logical order: element `u * ny + v` is the
    /// value at lattice node `(origin_x + u, origin_y + v)` (periodic). Writes into `out`.
    ///
    /// # Panics
    /// If `out.len() != patch_len()`.
    pub fn unrolled_into(&self, cell_idx: usize, out: &mut [f64]) {
        let (nx, ny) = (self.shape.nx, self.shape.ny);
        assert_eq!(out.len(), nx * ny);
        let [fx, fy] = self.map.offset[cell_idx];
        let phi = self.cell_phi(cell_idx);
        for u in 0..nx {
            let a = (u + fx) % nx;
            for v in 0..ny {
                let b = (v + fy) % ny;
                out[u * ny + v] = phi[a * ny + b].to_f64();
            }
        }
    }

    /// Scatters cell `cell_idx` onto a lattice-sized field (adds `φ_i` to `out`).
    pub fn add_to_lattice(&self, cell_idx: usize, out: &mut [f64]) {
        let ny = self.shape.ny;
        let lx = self.map.cell_x(&self.shape, cell_idx);
        let ly = self.map.cell_y(&self.shape, cell_idx);
        let phi = self.cell_phi(cell_idx);
        for (a, &x) in lx.iter().enumerate() {
            for (b, &y) in ly.iter().enumerate() {
                out[self.lattice.index(x as usize, y as usize)] += phi[a * ny + b].to_f64();
            }
        }
    }
}

impl<T: Real> Cells<T> {
    /// Bytes of heap memory held by the fields and their patch map.
    pub fn heap_bytes(&self) -> usize {
        self.phi.capacity() * std::mem::size_of::<T>() + self.map.heap_bytes()
    }

    /// The same cells stored in precision `U`, consuming `self`: without a copy when `U` is
    /// `T`, else as [`Cells::to_precision`].
    pub fn into_precision<U: Real>(self) -> Cells<U> {
        let any: Box<dyn std::any::Any> = Box::new(self);
        match any.downcast::<Cells<U>>() {
            Ok(same) => *same,
            Err(any) => any
                .downcast::<Self>()
                .expect("the box holds a Cells<T>")
                .to_precision(),
        }
    }

    /// The same cells with their fields stored in precision `U` (each value rounded once).
    pub fn to_precision<U: Real>(&self) -> Cells<U> {
        Cells {
            lattice: self.lattice,
            shape: self.shape.clone(),
            n_cells: self.n_cells,
            phi: self.phi.iter().map(|v| U::from_f64(v.to_f64())).collect(),
            map: self.map.clone(),
        }
    }
}

fn min_image_int(d: i64, l: i64) -> i64 {
    let w = d.rem_euclid(l);
    if 2 * w >= l {
        w - l
    } else {
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A split conserves the field node by node (to one rounding of the storage precision),
    /// puts the two parts on either side of the line, and a swap_remove moves the last cell
    /// into the freed slot with its patch.
    #[test]
    fn a_split_conserves_the_field_and_swap_remove_keeps_the_others() {
        let lattice = Lattice::new(48, 40);
        let shape = PatchShape::new(lattice, 12).unwrap();
        let centres = [[10.0, 10.0], [46.5, 20.0], [30.0, 30.0]];
        let cells64 = crate::init::discs(lattice, shape, &centres, 7.0, 2.5);
        fn check<T: Real>(mut cells: Cells<T>, tol: f64) {
            let before: Vec<f64> = cells.cell_phi(1).iter().map(|v| v.to_f64()).collect();
            let origin = cells.map().origin[1];
            let dir = [0.6f64, 0.8];
            // Across the periodic edge at x = 0.
            let new = cells.split(1, [46.5, 20.0], dir, 2.5);
            assert_eq!((new, cells.n_cells()), (3, 4));
            assert_eq!(cells.map().origin[3], origin);
            let (a, b) = (cells.cell_phi(1), cells.cell_phi(3));
            let mut worst: f64 = 0.0;
            for k in 0..before.len() {
                worst = worst.max((a[k].to_f64() + b[k].to_f64() - before[k]).abs());
            }
            assert!(worst <= tol, "{worst:e}");
            let sum: f64 = (0..before.len())
                .map(|k| a[k].to_f64() + b[k].to_f64() - before[k])
                .sum();
            assert!(sum.abs() <= tol * before.len() as f64, "{sum:e}");
            // Each part on its side: the first moment along the direction.
            let l = cells.lattice();
            let moment = |i: usize| -> f64 {
                let (mut m, mut w) = (0.0, 0.0);
                for x in 0..l.lx {
                    for y in 0..l.ly {
                        let v = cells.value_at(i, x, y);
                        let dx = crate::min_image(x as f64 - 46.5, l.lx as f64);
                        let dy = crate::min_image(y as f64 - 20.0, l.ly as f64);
                        m += v * (dx * dir[0] + dy * dir[1]);
                        w += v;
                    }
                }
                m / w
            };
            assert!(
                moment(1) > 2.0 && moment(3) < -2.0,
                "{} {}",
                moment(1),
                moment(3)
            );
            // Remove cell 0: the last (the new part) moves into slot 0 with its patch.
            let last: Vec<f64> = cells.cell_phi(3).iter().map(|v| v.to_f64()).collect();
            let kept: Vec<f64> = cells.cell_phi(2).iter().map(|v| v.to_f64()).collect();
            assert_eq!(cells.swap_remove(0), Some(3));
            assert_eq!(cells.n_cells(), 3);
            assert_eq!(cells.map().origin[0], origin);
            assert!(cells
                .cell_phi(0)
                .iter()
                .zip(&last)
                .all(|(a, b)| a.to_f64() == *b));
            assert!(cells
                .cell_phi(2)
                .iter()
                .zip(&kept)
                .all(|(a, b)| a.to_f64() == *b));
            assert_eq!(cells.swap_remove(2), None);
            assert_eq!(cells.phi().len(), 2 * cells.patch_len());
        }
        check(cells64.clone(), 2.0 * f64::EPSILON);
        check(
            cells64.into_precision::<f32>(),
            2.0 * f64::from(f32::EPSILON),
        );
    }

    /// A move keeps every value on its lattice node, and the wrapped columns and rows keep
    /// their far-edge values: exactly the move that only changes the origin and the storage
    /// offset (the paper's algorithm, rebuilt here with `from_storage`), but with the values
    /// rotated into logical order (offset `[0, 0]`). Across both periodic edges, by more than
    /// one node, twice in a row.
    #[test]
    fn recentre_keeps_values_on_their_nodes_and_stores_the_patch_in_logical_order() {
        let lattice = Lattice::new(40, 30);
        let shape = PatchShape::new(lattice, 3).unwrap();
        let mut cells = Cells::zeros(lattice, shape.clone(), &[[1.0, 2.0]]);
        let (nx, ny) = (7, 7);
        // Mark every node with a value encoding its lattice position.
        let xs: Vec<u32> = cells.map().cell_x(cells.shape(), 0).to_vec();
        let ys: Vec<u32> = cells.map().cell_y(cells.shape(), 0).to_vec();
        for a in 0..nx {
            for b in 0..ny {
                cells.phi_mut()[a * ny + b] = (xs[a] * 1000 + ys[b]) as f64;
            }
        }
        for (centre, shift) in [([38.2, 28.6], [-3, -3]), ([2.4, 27.2], [4, -2])] {
            // The offset-only move of the same patch.
            let old = cells.map().clone();
            let d = [shift[0] as i64, shift[1] as i64];
            let offset = [
                (old.offset[0][0] as i64 + d[0]).rem_euclid(nx as i64) as usize,
                (old.offset[0][1] as i64 + d[1]).rem_euclid(ny as i64) as usize,
            ];
            let origin = [
                (old.origin[0][0] as i64 + d[0]).rem_euclid(40) as usize,
                (old.origin[0][1] as i64 + d[1]).rem_euclid(30) as usize,
            ];
            let expected = Cells::from_storage(
                lattice,
                shape.clone(),
                cells.phi().to_vec(),
                vec![origin],
                vec![offset],
            )
            .unwrap();
            assert_eq!(cells.recentre(0, centre), d);
            assert_eq!(cells.map().origin[0], origin);
            assert_eq!(cells.map().offset[0], [0, 0], "stored in logical order");
            for x in 0..40 {
                for y in 0..30 {
                    assert_eq!(
                        cells.value_at(0, x, y),
                        expected.value_at(0, x, y),
                        "({x}, {y})"
                    );
                }
            }
            // Storage column a is lattice column origin + a.
            let xs2 = cells.map().cell_x(cells.shape(), 0);
            assert!((0..nx).all(|a| xs2[a] as usize == (origin[0] + a) % 40));
        }
        // The patch is centred on the rounded centre.
        assert_eq!(cells.map().origin[0], [40 - 1, 24]);
    }
}
