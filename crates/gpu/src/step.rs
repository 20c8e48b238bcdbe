//! The GPU backend: its construction from a tissue, the recording of steps, and what it
//! reads back.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc;
use std::sync::Arc;

use bytemuck::Zeroable;
use mechanics::backend::Backend;
use mechanics::{StepError, StepParams, Tissue};
use phasefield::{Lattice, PatchShape, Real};

use crate::bindings::{used_slots, Slot};
use crate::device::{Device, GpuError};
use crate::features::{self, Feature, Hook, Host, On, View};
use crate::kernels::{Buffers, Builder, Kernels, Role};
use crate::layout::{allocate, grid, GpuOptions, Layout};
use crate::memory::{bin_grid, bins, GpuMemory, Sizes};
use crate::shader::shader_source_split;
use crate::shared::{Chunk, Kind, Kinds, Params, CELL_STRIDE, MAX_KINDS, WG};

/// Steps recorded before they are submitted.
const BATCH: usize = 16;

/// One evaluation on the device ([`GpuBackend::evaluate`]).
#[derive(Debug, Clone)]
pub struct Evaluation {
    /// `R(φ)` of every cell, in logical patch order.
    pub rhs: Vec<f32>,
    /// Per lattice node (`x * ly + y`): `P`, `s2`, `Q_xx`, `Q_xy`.
    pub lattice: Vec<[f32; 4]>,
    /// Per cell, 12 floats: area, `S_xx`, `S_xy`, `φ_min`, `φ_max`, `F_x`, `F_y`, `v_x`,
    /// `v_y`, and the centre of the last step.
    pub cells: Vec<f32>,
}

/// The GPU backend: the state and every buffer of the step on the device, and the steps
/// recorded since they were last submitted.
///
/// Storage and arithmetic are f32 (the CPU default stores f32 and computes in f64): the cost
/// of the f32 arithmetic against the CPU is measured by the tests and docs/performance.md.
pub struct GpuBackend {
    dev: Device,
    kernels: Kernels,
    buffers: Buffers,
    /// The extensions of the model, each on or off for the tissue the backend was built for.
    features: Vec<Box<dyn Feature>>,
    /// The chunks of cells, `(lo, count)`.
    chunks: Vec<(usize, usize)>,
    /// The nodes in the first binding of each lattice array; the rest are in the second.
    lat_split: usize,
    lattice: Lattice,
    shape: PatchShape,
    n_cells: usize,
    npc: usize,
    params: Params,
    kinds: Kinds,
    /// The most cells the buffers hold (`[division] max_cells` with division).
    capacity: usize,
    /// The chunks of the cells there are now, `(lo, count)`: the first `active.len()` of
    /// `chunks`, the last of them perhaps partly filled.
    active: Vec<(usize, usize)>,
    /// Bytes copied from the device to the host so far ([`GpuBackend::bytes_read`]).
    bytes_read: Arc<AtomicU64>,
    groups_cells: (u32, u32),
    groups_nodes: (u32, u32),
    groups_bins: u32,
    encoder: Option<wgpu::CommandEncoder>,
    recorded: usize,
    /// The clock at the last sync or upload, and the size of every step queued since.
    base: (u64, f64),
    queued: Vec<f64>,
}

impl std::fmt::Debug for GpuBackend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GpuBackend")
            .field("adapter", &self.dev.describe())
            .field("n_cells", &self.n_cells)
            .field("chunks", &self.chunks.len())
            .finish_non_exhaustive()
    }
}

impl GpuBackend {
    /// Opens a device ([`Device::open`]) and builds the backend for `tissue` stepped with
    /// `step`.
    ///
    /// # Errors
    /// See [`GpuBackend::on`].
    pub fn new<T: Real>(tissue: &Tissue<T>, step: &StepParams) -> Result<Self, GpuError> {
        Self::check(tissue, step)?;
        Self::on(Device::open()?, tissue, step)
    }

    /// What the GPU backend refuses in a tissue and step, before any device is opened: the
    /// model's extensions (each named), full-domain storage, and forward Euler.
    ///
    /// # Errors
    /// [`GpuError::Unsupported`] or [`GpuError::Setting`].
    pub fn check<T: Real>(tissue: &Tissue<T>, step: &StepParams) -> Result<(), GpuError> {
        let ext = features::unsupported(tissue.extensions(), tissue.params());
        if !ext.is_empty() {
            return Err(GpuError::Unsupported(ext.join(", ")));
        }
        let kinds = tissue.populations().kinds().len();
        if kinds > MAX_KINDS {
            return Err(GpuError::Setting(format!(
                "the GPU backend holds at most {MAX_KINDS} populations, and this scene has {kinds}: merge some [[population]] tables or run with backend = \"cpu\""
            )));
        }
        if tissue.cells().shape().margin.is_none() {
            return Err(GpuError::Setting(
                "the GPU backend needs patches: [integrator] margin = 0 (the full-domain reference) runs with backend = \"cpu\"".into(),
            ));
        }
        if step.npc == 0 {
            return Err(GpuError::Setting(
                "the GPU backend runs Heun's method, with at least one corrector: set [integrator] npc = 1 (forward Euler, npc = 0, runs with backend = \"cpu\")".into(),
            ));
        }
        Ok(())
    }

    /// The backend on an open device.
    ///
    /// # Errors
    /// [`GpuError::Unsupported`] or [`GpuError::Setting`] (see [`GpuBackend::check`]);
    /// [`GpuError::TooLarge`] when a φ array passes the device's largest binding (the
    /// figures in the message).
    pub fn on<T: Real>(
        dev: Device,
        tissue: &Tissue<T>,
        step: &StepParams,
    ) -> Result<Self, GpuError> {
        Self::with_options(dev, tissue, step, GpuOptions::default())
    }

    /// The backend on an open device, laid out as `options` say.
    ///
    /// The per-cell φ arrays are split into chunks of at most the device's largest binding;
    /// when the buffers do not fit the device's memory, the error gives the estimate.
    ///
    /// # Errors
    /// As [`GpuBackend::on`].
    pub fn with_options<T: Real>(
        dev: Device,
        tissue: &Tissue<T>,
        step: &StepParams,
        options: GpuOptions,
    ) -> Result<Self, GpuError> {
        Self::check(tissue, step)?;
        let cells = tissue.cells();
        let (lattice, shape, n_now) = (cells.lattice(), cells.shape().clone(), cells.n_cells());
        // With division, every per-cell buffer holds the clock's most cells (`max_cells`):
        // the events change the number of cells between steps, not the buffers.
        let n = tissue
            .proliferation()
            .map_or(n_now, |c| c.max_cells.max(n_now));
        let layout = Layout::fit(&dev, lattice, &shape, n, options)?;
        let on = On::of(tissue);
        let features = features::all(on);
        let sizes = Sizes::of(
            lattice,
            &shape,
            n,
            step.npc,
            layout.split,
            layout.chunks.len() > 1,
            on,
        );
        // Allocation failures (the state does not fit the device) are caught here and
        // reported with the estimate, not left to a later panic.
        let oom = dev.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let buffers = allocate(&dev, lattice, &shape, &layout, &sizes, step.npc);
        let (_, cap) = bins(lattice, &shape, n);
        let source = shader_source_split(
            &shape,
            tissue.params().pressure,
            cap,
            layout.split as u32,
            options.variant,
        );
        let used = used_slots(&source).map_err(GpuError::Setting)?;
        let module = dev
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("step"),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            });
        let builder = Builder {
            device: &dev.device,
            module: &module,
            used: used.into_iter().collect(),
            buffers: &buffers,
            flags: features
                .iter()
                .map(|f| (f.constant(), f64::from(u8::from(f.on()))))
                .collect(),
        };
        let kernels = Kernels::new(&builder, &features);
        if let Some(e) = pollster::block_on(oom.pop()) {
            let mem = GpuMemory::estimate(lattice, &shape, n, step.npc, &tissue.parts());
            return Err(GpuError::TooLarge(format!(
                "{n} cells on patches of {}×{} need {} on the device ({}), which could not allocate them ({e}); reduce [cells] count or [integrator] margin",
                shape.nx,
                shape.ny,
                mem.describe(),
                dev.describe()
            )));
        }
        let groups_cells = grid(layout.per_chunk as u32);
        let (nbx, nby) = bin_grid(lattice, &shape);
        let params = Params {
            xi: 1.0,
            lx: lattice.lx as u32,
            ly: lattice.ly as u32,
            nbx,
            nby,
            n_cells: n as u32,
            grid_x: groups_cells.0,
            bound: mechanics::PHI_BOUND as f32,
            ..Params::zeroed()
        };
        let mut backend = Self {
            kernels,
            buffers,
            features,
            lat_split: lattice.len().min(layout.split),
            chunks: layout.chunks,
            kinds: [Kind::zeroed(); MAX_KINDS],
            capacity: n,
            active: Vec::new(),
            bytes_read: Arc::new(AtomicU64::new(0)),
            lattice,
            shape,
            n_cells: n_now,
            npc: step.npc,
            params,
            groups_cells,
            groups_nodes: grid((lattice.len() as u32).div_ceil(WG)),
            groups_bins: (nbx * nby).div_ceil(WG),
            encoder: None,
            recorded: 0,
            base: (tissue.iteration(), tissue.time()),
            queued: Vec::new(),
            dev,
        };
        backend.upload_state(tissue)?;
        Ok(backend)
    }

    /// The adapter, described.
    pub fn adapter(&self) -> String {
        self.dev.describe()
    }

    /// The buffer at `slot` (one that does not change with the evaluation).
    fn buf(&self, slot: Slot) -> &wgpu::Buffer {
        &self.buffers.fixed[&slot]
    }

    /// What the features read of `tissue`, with the device's clock.
    fn view<'a, T: Real>(&self, tissue: &'a Tissue<T>) -> View<'a> {
        View {
            base: self.base,
            ..View::of(tissue)
        }
    }

    /// The uniforms of a step of `tissue` of size `dt`: the parameters and every population's
    /// constants, as the host's step takes them ([`mechanics::terms::Populations::constants`]:
    /// with populations of their own ζ, the force's ζ is 1 and each `S_i` is weighted by its
    /// cell's), then each feature's fields.
    fn uniforms_of<T: Real>(&self, tissue: &Tissue<T>, dt: f64) -> (Params, Kinds) {
        let p = tissue.params();
        let c = p.energy.coefficients();
        let (zeta, constants) = tissue.populations().constants(p, tissue.active());
        let mut kinds = [Kind::zeroed(); MAX_KINDS];
        for (k, c) in kinds.iter_mut().zip(&constants) {
            *k = Kind {
                double_well: c.coef.double_well as f32,
                gradient: c.coef.gradient as f32,
                area: c.coef.area as f32,
                inv_target_area: c.coef.inv_target_area as f32,
                xi: c.xi as f32,
                zeta_weight: c.zeta_weight as f32,
                ..Kind::zeroed()
            };
        }
        let mut params = Params {
            double_well: c.double_well as f32,
            gradient: c.gradient as f32,
            area: c.area as f32,
            inv_target_area: c.inv_target_area as f32,
            repulsion: c.repulsion as f32,
            zeta: zeta as f32,
            xi: p.xi as f32,
            dt: dt as f32,
            ..self.params
        };
        let view = View {
            n_kinds: constants.len(),
            ..self.view(tissue)
        };
        for f in &self.features {
            f.uniforms(&view, &mut params, &mut kinds);
        }
        (params, kinds)
    }

    /// Takes the uniforms of a step of `tissue` of size `dt`, and the features' data when
    /// what they read changed, writing what changed; whether the uniforms did.
    fn set_uniforms<T: Real>(&mut self, tissue: &Tissue<T>, dt: f64) -> bool {
        self.write_features(tissue, false);
        let (params, kinds) = self.uniforms_of(tissue, dt);
        let changed = params != self.params || kinds != self.kinds;
        if changed {
            // A change (the activity switch) applies from this step on: the steps recorded
            // before it go first.
            self.flush();
            self.params = params;
            self.kinds = kinds;
            let q = &self.dev.queue;
            q.write_buffer(self.buf(Slot::Params), 0, bytemuck::bytes_of(&self.params));
            q.write_buffer(self.buf(Slot::Kinds), 0, bytemuck::cast_slice(&self.kinds));
        }
        changed
    }

    /// Writes each feature's data for `tissue` (at an upload of its state, `upload`, or
    /// before a step), after the steps recorded before it.
    fn write_features<T: Real>(&mut self, tissue: &Tissue<T>, upload: bool) {
        let view = self.view(tissue);
        let mut writes = Vec::new();
        for f in &mut self.features {
            writes.extend(f.data(&view, upload));
        }
        if !writes.is_empty() {
            self.flush();
        }
        for (slot, bytes) in writes {
            self.dev.queue.write_buffer(self.buf(slot), 0, &bytes);
        }
    }

    fn upload_state<T: Real>(&mut self, tissue: &Tissue<T>) -> Result<(), GpuError> {
        let cells = tissue.cells();
        if cells.n_cells() > self.capacity || cells.shape().len() != self.shape.len() {
            return Err(GpuError::Setting(format!(
                "the backend was built for at most {} cells, and the tissue has {}: build a new backend",
                self.capacity,
                cells.n_cells()
            )));
        }
        self.n_cells = cells.n_cells();
        self.params.n_cells = self.n_cells as u32;
        // The chunks the cells fill now, and their uniforms (the last filled one ends the
        // lattice pass's sums).
        self.active = self
            .chunks
            .iter()
            .map(|&(lo, cap)| (lo, cap.min(self.n_cells.saturating_sub(lo))))
            .take_while(|&(_, count)| count > 0)
            .collect();
        if self.active.is_empty() {
            self.active.push((0, 0));
        }
        for (k, &(lo, count)) in self.active.iter().enumerate() {
            let v = Chunk {
                lo: lo as u32,
                count: count as u32,
                first: u32::from(k == 0),
                last: u32::from(k + 1 == self.active.len()),
            };
            self.dev
                .queue
                .write_buffer(&self.buffers.chunk_info[k], 0, bytemuck::bytes_of(&v));
        }
        let plen = self.shape.len();
        let mut values = vec![0.0f32; self.n_cells * plen];
        let mut patch = vec![0.0f64; plen];
        for (i, out) in values.chunks_exact_mut(plen).enumerate() {
            cells.unrolled_into(i, &mut patch);
            for (o, &v) in out.iter_mut().zip(&patch) {
                *o = v as f32;
            }
        }
        let origins: Vec<[u32; 2]> = cells
            .map()
            .origin
            .iter()
            .map(|o| [o[0] as u32, o[1] as u32])
            .collect();
        let q = &self.dev.queue;
        for (&(lo, count), buf) in self.active.iter().zip(&self.buffers.phi) {
            q.write_buffer(
                buf,
                0,
                bytemuck::cast_slice(&values[lo * plen..(lo + count) * plen]),
            );
        }
        q.write_buffer(self.buf(Slot::Origin), 0, bytemuck::cast_slice(&origins));
        q.write_buffer(self.buf(Slot::Status), 0, bytemuck::cast_slice(&[0u32; 4]));
        // The cell buffer: the centres and each slot's population index (slot 11, a u32's
        // bits); the rest is computed by every evaluation before it is read.
        let mut per_cell = vec![0.0f32; self.n_cells * CELL_STRIDE];
        let (ids, pops) = (tissue.cell_ids(), tissue.populations());
        for ((row, centre), &id) in per_cell
            .chunks_exact_mut(CELL_STRIDE)
            .zip(tissue.centres())
            .zip(ids)
        {
            row[9] = centre[0] as f32;
            row[10] = centre[1] as f32;
            row[11] = f32::from_bits(pops.population(id) as u32);
        }
        q.write_buffer(self.buf(Slot::Cell), 0, bytemuck::cast_slice(&per_cell));
        self.base = (tissue.iteration(), tissue.time());
        self.write_features(tissue, true);
        self.queued.clear();
        let dt = f64::from(self.params.dt);
        self.params.dt = f32::NAN; // written whatever it was
        self.set_uniforms(tissue, dt);
        Ok(())
    }

    /// Submits the steps recorded so far.
    fn flush(&mut self) {
        if let Some(enc) = self.encoder.take() {
            self.dev.queue.submit(Some(enc.finish()));
            self.recorded = 0;
        }
    }

    /// Records one step into the pending command encoder.
    fn record(&mut self) {
        self.record_passes(false);
    }

    /// One evaluation of the current state, as a step's first (with its check), without
    /// stepping: `R(φ)`, the lattice sums and the per-cell quantities, read back.
    ///
    /// # Errors
    /// [`GpuError::Lost`].
    pub fn evaluate<T: Real>(
        &mut self,
        tissue: &Tissue<T>,
        dt: f64,
    ) -> Result<Evaluation, GpuError> {
        self.flush();
        self.set_uniforms(tissue, dt);
        self.record_passes(true);
        self.flush();
        let plen = self.shape.len();
        let rhs = self.read_chunks(&self.buffers.k1, plen)?;
        let lat = self.read_lattice()?;
        Ok(Evaluation {
            rhs: bytemuck::cast_slice(&rhs).to_vec(),
            lattice: bytemuck::cast_slice(&lat).to_vec(),
            cells: self.cell_quantities()?,
        })
    }

    fn record_passes(&mut self, evaluate_only: bool) {
        let enc = self.encoder.get_or_insert_with(|| {
            self.dev
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("steps"),
                })
        });
        let k = &self.kernels;
        let cells = self.groups_cells;
        let nodes = self.groups_nodes;
        let per_cell = ((self.n_cells as u32).div_ceil(WG), 1);
        // The chunks the cells fill now.
        let na = self.active.len();
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("step"),
            timestamp_writes: None,
        });
        // The bins of this step's patch origins.
        let bins = (self.groups_bins, 1);
        k.bin_clear.dispatch(&mut pass, Role::Predict, 0, bins);
        k.bin_fill.dispatch(&mut pass, Role::Predict, 0, per_cell);
        k.bin_sort.dispatch(&mut pass, Role::Predict, 0, bins);
        // k1 = R(φ) with the check, and the predictor.
        let passes = if evaluate_only { 0 } else { self.npc };
        // Each evaluation's cell pass, role and force pass, and whether it is a corrector.
        let first = (&k.cell_check, Role::Predict, &k.predict, false);
        for (cell, role, force, corrector) in
            std::iter::once(first).chain((0..passes).map(|pass| {
                let last = pass + 1 == self.npc;
                if last {
                    (&k.cell, Role::Last(pass % 2), &k.correct_last, true)
                } else {
                    (&k.cell, Role::Middle(pass % 2), &k.correct, true)
                }
            }))
        {
            // Each pass over every chunk before the next pass: the lattice sums need every
            // cell's area and shape, the forces every node's sums (chunk by chunk, in order).
            for c in 0..na {
                cell.dispatch(&mut pass, role, c, cells);
            }
            for c in 0..na {
                k.lattice.dispatch(&mut pass, role, c, nodes);
            }
            // The features' lattice kernels (adhesion's Laplacian of s1) once the last chunk
            // has written its sums.
            for extra in k.at(Hook::Lattice) {
                extra.dispatch(&mut pass, role, 0, nodes);
            }
            for c in 0..na {
                force.dispatch(&mut pass, role, c, cells);
            }
            // The features' per-cell updates (the polarity's predictor after the first
            // evaluation, its corrector after the others); not in an evaluation alone.
            if !evaluate_only {
                for extra in k.at(Hook::Force { corrector }) {
                    extra.dispatch(&mut pass, role, 0, per_cell);
                }
            }
        }
        if !evaluate_only {
            k.count.dispatch(&mut pass, Role::Predict, 0, (1, 1));
        }
        drop(pass);
        self.recorded += 1;
    }

    /// Copies the lattice sums (`P`, `s2`, `Q_xx`, `Q_xy` per node) to the host, from both
    /// bindings.
    fn read_lattice(&self) -> Result<Vec<u8>, GpuError> {
        let mut lat = self.read(self.buf(Slot::Lat), self.lat_split as u64 * 16)?;
        let rest = self.lattice.len() - self.lat_split;
        if rest > 0 {
            lat.extend(self.read(self.buf(Slot::LatHi), rest as u64 * 16)?);
        }
        Ok(lat)
    }

    /// Copies a per-chunk array (`per_cell` floats a cell) to the host, chunk after chunk.
    fn read_chunks(&self, arrays: &[wgpu::Buffer], per_cell: usize) -> Result<Vec<u8>, GpuError> {
        let mut out = Vec::with_capacity(self.n_cells * per_cell * 4);
        for (&(_, count), buf) in self.active.iter().zip(arrays) {
            out.extend(self.read(buf, (count * per_cell * 4) as u64)?);
        }
        Ok(out)
    }

    /// Submits the steps queued so far and waits until the device has run them, without
    /// reading anything back (for timing).
    ///
    /// # Errors
    /// [`GpuError::Lost`].
    pub fn wait(&mut self) -> Result<(), GpuError> {
        self.flush();
        self.dev
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| GpuError::Lost(e.to_string()))
    }

    /// Bytes the step moves to and from device memory per node-update (one cell's patch node
    /// in one step), counted from the kernels: per evaluation the cell pass reads φ (4), the
    /// gather reads φ once more (4), the force pass reads φ and the node's sums (4 + 16) and
    /// writes `R` and the new φ (8; the corrector also reads `R` and φⁿ, 8 more); the lattice
    /// sums write 16 bytes a lattice node, 2 evaluations a step, counted per patch node with
    /// `lattice_nodes / patch_nodes`. With `K` chunks the lattice pass runs once per chunk
    /// over the whole lattice, and every chunk but the last writes its partial sums (32 bytes
    /// a node) that the next reads (32 more): `64 (K − 1)` bytes a lattice node and
    /// evaluation (about 39 B per node-update at 10⁶ cells in 3 chunks). Neighbours of the
    /// stencil and the bins' lists are taken as cached.
    ///
    /// The extensions add, per evaluation: walls 8 bytes a patch node (the force pass reads
    /// (w, ∇²w)) and 8 a lattice node (the lattice pass reads them); adhesion 4 bytes a patch
    /// node (the force pass reads ∇²s1) and 44 a lattice node (the lattice pass writes s1, the
    /// adhesion pass reads it, writes ∇²s1 and reads and writes `P, s2, Q`); polarity 88
    /// bytes a cell and evaluation (0.2 B a node-update on patches of 30²).
    pub fn bytes_per_node_update(&self) -> f64 {
        let predictor = 4.0 + 4.0 + 4.0 + 16.0 + 8.0;
        let corrector = predictor + 8.0;
        let correctors = self.npc as f64;
        let per_patch_node =
            self.lattice.len() as f64 / (self.n_cells * self.shape.len()).max(1) as f64;
        let chunks = 64.0 * self.active.len().saturating_sub(1) as f64;
        let mut parts = features::Traffic::default();
        for f in self.features.iter().filter(|f| f.on()) {
            let t = f.traffic();
            parts.patch_node += t.patch_node;
            parts.lattice_node += t.lattice_node;
            parts.cell += t.cell;
        }
        let evaluations = 1.0 + correctors;
        let lattice = (16.0 + chunks + parts.lattice_node) * evaluations * per_patch_node;
        let per_cell = parts.cell * evaluations / self.shape.len() as f64;
        predictor + correctors * corrector + parts.patch_node * evaluations + lattice + per_cell
    }

    /// The number of chunks the per-cell arrays are split into.
    pub fn n_chunks(&self) -> usize {
        self.active.len()
    }

    /// Copies `bytes` of `buffer` to the host.
    fn read(&self, buffer: &wgpu::Buffer, bytes: u64) -> Result<Vec<u8>, GpuError> {
        let d = &self.dev.device;
        let staging = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: bytes.max(16),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        enc.copy_buffer_to_buffer(buffer, 0, &staging, 0, bytes);
        self.bytes_read.fetch_add(bytes, Ordering::Relaxed);
        self.dev.queue.submit(Some(enc.finish()));
        let (tx, rx) = mpsc::channel();
        staging
            .slice(..bytes)
            .map_async(wgpu::MapMode::Read, move |r| {
                let _ = tx.send(r);
            });
        d.poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| GpuError::Lost(e.to_string()))?;
        rx.recv()
            .map_err(|e| GpuError::Lost(e.to_string()))?
            .map_err(|e| GpuError::Lost(e.to_string()))?;
        let data = staging
            .slice(..bytes)
            .get_mapped_range()
            .map_err(|e| GpuError::Lost(e.to_string()))?
            .to_vec();
        staging.unmap();
        Ok(data)
    }

    /// The per-cell quantities of the last evaluation, per slot: area, `S_xx`, `S_xy`,
    /// `φ_min`, `φ_max`, `F`, `v` and the centre (12 floats each, the last unused).
    ///
    /// # Errors
    /// [`GpuError::Lost`].
    pub fn cell_quantities(&mut self) -> Result<Vec<f32>, GpuError> {
        self.flush();
        self.cell_quantities_now()
    }

    /// Bytes copied from the device to the host since the backend was made: what a test
    /// reads to show that the observables bring back no fields.
    pub fn bytes_read(&self) -> u64 {
        self.bytes_read.load(Ordering::Relaxed)
    }

    /// The counter of [`GpuBackend::bytes_read`], to read while a simulation owns the backend.
    pub fn bytes_read_counter(&self) -> Arc<AtomicU64> {
        Arc::clone(&self.bytes_read)
    }

    /// Whether a queued step failed its check or overflowed a bin (read from the status).
    fn failed(&self) -> Result<bool, GpuError> {
        let status = self.read(self.buf(Slot::Status), 16)?;
        let [failed, overflow, _, _]: [u32; 4] = bytemuck::pod_read_unaligned(&status);
        Ok(failed != 0 || overflow != 0)
    }

    /// The observables of the device's current state ([`mechanics::Observables`], as
    /// [`Tissue::observe`] computes them on the host): one evaluation of the state, the
    /// tissue velocity `Σ φ_i v_i` per node and `Σ |v|²` reduced per workgroup, then only the
    /// per-cell quantities (48 bytes a cell) and the workgroups' sums (4 bytes per 256 nodes)
    /// come back, never the fields. `None` when a queued step failed, or the evaluation did
    /// (the sync reports it).
    ///
    /// # Errors
    /// [`GpuError::Lost`].
    pub fn observables<T: Real>(
        &mut self,
        tissue: &Tissue<T>,
    ) -> Result<Option<mechanics::Observables>, GpuError> {
        // (A queued step that failed leaves the status set, and the kernels below halt on it:
        // the one read of the status after them says both.)
        self.set_uniforms(tissue, f64::from(self.params.dt));
        self.record_passes(true);
        {
            let enc = self.encoder.as_mut().expect("just recorded");
            let k = &self.kernels;
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("observables"),
                timestamp_writes: None,
            });
            for c in 0..self.active.len() {
                k.velocity_sums
                    .dispatch(&mut pass, Role::Predict, c, self.groups_nodes);
            }
            k.velocity_reduce
                .dispatch(&mut pass, Role::Predict, 0, self.groups_nodes);
        }
        self.flush();
        if self.failed()? {
            return Ok(None);
        }
        let q = self.cell_quantities_now()?;
        let (nx, ny) = self.groups_nodes;
        let parts = self.read(self.buf(Slot::V2Part), u64::from(nx * ny) * 4)?;
        let v2: f64 = bytemuck::cast_slice::<u8, f32>(&parts)
            .iter()
            .map(|&v| f64::from(v))
            .sum();
        let o = mechanics::Observables::from_cells(
            v2 / self.lattice.len() as f64,
            q.chunks_exact(CELL_STRIDE)
                .map(|row| mechanics::CellObservables::from(&cell_state_of(row))),
        );
        Ok(Some(o))
    }

    /// What the last evaluation of the queued steps computed ([`Backend::evaluation`]): the
    /// per-cell quantities (48 bytes a cell) and, when `pressure`, `P` per lattice node (16
    /// bytes a node, of which the first 4 are kept). `None` when a queued step failed.
    ///
    /// # Errors
    /// [`GpuError::Lost`].
    pub fn device_evaluation(
        &mut self,
        pressure: bool,
    ) -> Result<Option<mechanics::backend::DeviceEvaluation>, GpuError> {
        self.flush();
        if self.failed()? {
            return Ok(None);
        }
        let q = self.cell_quantities_now()?;
        let cells = q.chunks_exact(CELL_STRIDE).map(cell_state_of).collect();
        let pressure = if pressure {
            let lat = self.read_lattice()?;
            let lat: &[[f32; 4]] = bytemuck::cast_slice(&lat);
            Some(lat.iter().map(|v| f64::from(v[0])).collect())
        } else {
            None
        };
        Ok(Some(mechanics::backend::DeviceEvaluation {
            cells,
            pressure,
        }))
    }

    /// The per-cell quantities as they are on the device now (after a flush).
    fn cell_quantities_now(&self) -> Result<Vec<f32>, GpuError> {
        let bytes = self.read(
            self.buf(Slot::Cell),
            (self.n_cells * CELL_STRIDE * 4) as u64,
        )?;
        Ok(bytemuck::cast_slice(&bytes).to_vec())
    }

    /// The state on the device: every cell's field in logical patch order and the patches'
    /// origins.
    ///
    /// # Errors
    /// [`GpuError::Lost`].
    pub fn state(&mut self) -> Result<(Vec<f32>, Vec<[usize; 2]>), GpuError> {
        self.flush();
        let phi = self.read_chunks(&self.buffers.phi, self.shape.len())?;
        let origin = self.read(self.buf(Slot::Origin), (self.n_cells * 8) as u64)?;
        let origin: &[[u32; 2]] = bytemuck::cast_slice(&origin);
        Ok((
            bytemuck::cast_slice(&phi).to_vec(),
            origin
                .iter()
                .map(|o| [o[0] as usize, o[1] as usize])
                .collect(),
        ))
    }

    fn error(message: String) -> StepError {
        StepError::Backend {
            backend: "gpu".into(),
            message,
        }
    }
}

impl<T: Real> Backend<T> for GpuBackend {
    fn supports(&self, part: mechanics::Part) -> bool {
        features::SUPPORTED.contains(&part)
    }

    fn name(&self) -> &str {
        "gpu"
    }

    fn step(&mut self, tissue: &Tissue<T>, params: &StepParams) -> Result<(), StepError> {
        if params.npc != self.npc {
            return Err(Self::error(format!(
                "the backend was built for {} corrector passes, and the step asks for {}",
                self.npc, params.npc
            )));
        }
        let view = self.view(tissue);
        for f in &self.features {
            f.check(&view).map_err(Self::error)?;
        }
        self.set_uniforms(tissue, params.dt);
        self.record();
        self.queued.push(params.dt);
        if self.recorded >= BATCH {
            self.flush();
        }
        Ok(())
    }

    fn sync(&mut self, tissue: &mut Tissue<T>) -> Result<(), StepError> {
        self.flush();
        let status = self
            .read(self.buf(Slot::Status), 16)
            .map_err(|e| Self::error(e.to_string()))?;
        let status: [u32; 4] = bytemuck::pod_read_unaligned(&status);
        let [failed, overflow, steps, cell] = status;
        let (phi, origins) = self.state().map_err(|e| Self::error(e.to_string()))?;
        let quantities = self
            .cell_quantities()
            .map_err(|e| Self::error(e.to_string()))?;
        let centres: Vec<[f64; 2]> = if steps > 0 {
            quantities
                .chunks_exact(CELL_STRIDE)
                .map(|c| [f64::from(c[9]), f64::from(c[10])])
                .collect()
        } else {
            tissue.centres().to_vec()
        };
        tissue.set_state_from_device(&phi, &origins, &centres);
        // Each feature's state the host keeps (the polarity's angles), read back and written
        // into the tissue's terms.
        let mut rows = Vec::with_capacity(self.features.len());
        for f in &self.features {
            let Some((slot, per_cell)) = f.readback() else {
                rows.push(Vec::new());
                continue;
            };
            let bytes = self
                .read(self.buf(slot), (self.n_cells * per_cell) as u64)
                .map_err(|e| Self::error(e.to_string()))?;
            let r: Vec<f32> = bytemuck::cast_slice(&bytes).to_vec();
            let ids = tissue.cell_ids().to_vec();
            let host = Host {
                terms: tissue.terms_mut(),
                ids: &ids,
            };
            f.sync(&r, host).map_err(Self::error)?;
            rows.push(r);
        }
        let done = steps as usize;
        let time = self.base.1 + self.queued.iter().take(done).sum::<f64>();
        let iteration = self.base.0 + done as u64;
        let dt = self.queued.get(done).copied().unwrap_or(0.0);
        self.queue_reset();
        self.base = (iteration, time);
        if overflow != 0 {
            tissue.set_clock(iteration, time);
            return Err(Self::error(format!(
                "more cells than a bin of the gather holds ({} per bin) met in one place; the cells are far denser than a confluent tissue: check the initial state",
                bins(self.lattice, &self.shape, self.n_cells).1
            )));
        }
        if failed != 0 {
            tissue.set_clock(iteration, time);
            let slot = cell as usize;
            let q = &quantities[slot * CELL_STRIDE..(slot + 1) * CELL_STRIDE];
            let (lo, hi) = (f64::from(q[3]), f64::from(q[4]));
            // A feature's own failure (the polarity's unstable step).
            let own = self
                .features
                .iter()
                .zip(&rows)
                .find_map(|(f, r)| f.unstable(failed, r, slot));
            if let Some((term, stiffness)) = own {
                return Err(StepError::TermUnstable {
                    step: iteration,
                    time,
                    term: term.into(),
                    cell: tissue.cell_ids()[slot],
                    stiffness,
                    dt,
                });
            }
            return Err(if failed == 2 {
                StepError::NonFinite {
                    step: iteration,
                    time,
                    cell_idx: slot,
                }
            } else {
                StepError::Unstable {
                    step: iteration,
                    time,
                    cell_idx: slot,
                    phi: if lo < -mechanics::PHI_BOUND { lo } else { hi },
                    dt,
                }
            });
        }
        Ok(())
    }

    fn upload(&mut self, tissue: &Tissue<T>) -> Result<(), StepError> {
        self.flush();
        self.upload_state(tissue)
            .map_err(|e| Self::error(e.to_string()))
    }

    fn evaluation(
        &mut self,
        tissue: &Tissue<T>,
        pressure: bool,
    ) -> Result<Option<mechanics::backend::DeviceEvaluation>, StepError> {
        let _ = tissue;
        self.device_evaluation(pressure)
            .map_err(|e| Self::error(e.to_string()))
    }

    fn observe(&mut self, tissue: &Tissue<T>) -> Result<Option<mechanics::Observables>, StepError> {
        self.observables(tissue)
            .map_err(|e| Self::error(e.to_string()))
    }
}

/// A cell's row of the cell buffer (area, `S_xx`, `S_xy`, `φ_min`, `φ_max`, `F`, `v`, the
/// centre, the population) as the host's per-cell quantities (the terms' force is not kept).
fn cell_state_of(row: &[f32]) -> mechanics::CellState {
    let c = |k: usize| f64::from(row[k]);
    let mut st = mechanics::CellState::default();
    st.area = c(0);
    st.shape = mechanics::TracelessTensor::from([c(1), c(2)]);
    st.force = mechanics::Vector2::new(c(5), c(6));
    st.velocity = mechanics::Vector2::new(c(7), c(8));
    st.phi_min = c(3);
    st.phi_max = c(4);
    st
}

impl GpuBackend {
    /// Clears the step counter and the queue after a sync.
    fn queue_reset(&mut self) {
        self.queued.clear();
        self.dev
            .queue
            .write_buffer(self.buf(Slot::Status), 8, bytemuck::cast_slice(&[0u32]));
    }
}
