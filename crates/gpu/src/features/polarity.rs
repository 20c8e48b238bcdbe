//! Self-propulsion along a polarity (the built-in `[polarity]` term, docs/model.md §11.1):
//! each cell's angle and its Heun step's scratch, a per-cell kernel of its own
//! (`polarity_update`, after each evaluation's force pass), the propulsion in the force pass,
//! and the noise drawn by Philox from the host's key (`wgsl/polarity.wgsl`).

use super::{Dims, Extra, Feature, Hook, Host, Traffic, View};
use crate::bindings::Slot;
use crate::shared::{Kinds, Params};

/// Floats per cell of the polarity's buffer (`POL_STRIDE` in the kernels).
pub(crate) const POL_STRIDE: usize = 8;

/// The failure code the polarity's update writes when Heun's step for θ is unstable.
const UNSTABLE: u32 = 3;

/// The polarity on the device.
pub(crate) struct Polarity {
    on: bool,
}

impl Polarity {
    pub fn new(on: bool) -> Self {
        Self { on }
    }
}

/// The code of what a polarity aligns to in the kernels (`Params::pol_align`); `None` for a
/// rule they do not know.
fn align_code(align: mechanics::terms::Align) -> Option<u32> {
    use mechanics::terms::Align;
    match align {
        Align::None => Some(0),
        Align::Velocity => Some(1),
        Align::Force => Some(2),
        Align::Shape => Some(3),
        _ => None,
    }
}

/// The polarity's angle of every identity, as the host holds it.
fn angles(terms: &mechanics::terms::Terms) -> Vec<f64> {
    terms
        .state("polarity")
        .map(<[f64]>::to_vec)
        .unwrap_or_default()
}

impl Feature for Polarity {
    fn wgsl(&self) -> &'static str {
        include_str!("../wgsl/polarity.wgsl")
    }

    fn constant(&self) -> &'static str {
        "POLARITY"
    }

    fn on(&self) -> bool {
        self.on
    }

    fn buffers(&self, dims: Dims) -> Vec<(Slot, u64)> {
        vec![(Slot::Pol, dims.cells * POL_STRIDE as u64 * 4)]
    }

    fn kernels(&self) -> &'static [Extra] {
        &[
            Extra {
                entry: "polarity_update",
                hook: Hook::Force { corrector: false },
            },
            Extra {
                entry: "polarity_update",
                hook: Hook::Force { corrector: true },
            },
        ]
    }

    /// Each population's propulsion, noise amplitude `√(2 D_r)` and alignment rate; the rule,
    /// the propulsion's form, contact inhibition, the activity switch and the noise's key.
    fn uniforms(&self, view: &View<'_>, params: &mut Params, kinds: &mut Kinds) {
        let polarity = view.terms.polarity();
        if let Some((_, pol)) = polarity {
            for (k, kind) in kinds.iter_mut().enumerate().take(view.n_kinds) {
                let [alpha, d_r, rate] = pol.values(k);
                kind.alpha = alpha as f32;
                kind.noise = (2.0 * d_r).sqrt() as f32;
                kind.align_rate = rate as f32;
            }
        }
        let seed = view.terms.seed();
        let iteration = view.base.0;
        params.pol_align = polarity.and_then(|(_, p)| align_code(p.align)).unwrap_or(0);
        params.pol_density = polarity.map_or(0, |(_, p)| {
            u32::from(p.propulsion == mechanics::terms::Propulsion::Density)
        });
        params.pol_inhibition = polarity.map_or(0.0, |(_, p)| p.contact_inhibition as f32);
        params.pol_active = u32::from(view.active);
        params.seed_lo = seed as u32;
        params.seed_hi = (seed >> 32) as u32;
        params.step_lo = iteration as u32;
        params.step_hi = (iteration >> 32) as u32;
        params.pol_stage = polarity.map_or(0, |(t, _)| (t as u32) << 16);
    }

    /// The angle of each slot, what the last step evaluation computed for the cell as the
    /// host's terms keep it (zero for a run that starts), and its identity (the noise's key).
    fn data(&mut self, view: &View<'_>, upload: bool) -> Vec<(Slot, Vec<u8>)> {
        if !upload || !self.on {
            return Vec::new();
        }
        let theta = angles(view.terms);
        let mut rows = vec![0.0f32; view.ids.len() * POL_STRIDE];
        for (row, &id) in rows.chunks_exact_mut(POL_STRIDE).zip(view.ids) {
            row[0] = theta[id] as f32;
            if let Some(last) = view.terms.last_evaluation(id) {
                row[4] = last.area as f32;
                row[5] = last.force.x as f32;
                row[6] = last.force.y as f32;
            }
            row[7] = f32::from_bits(id as u32);
        }
        vec![(Slot::Pol, bytemuck::cast_slice(&rows).to_vec())]
    }

    fn readback(&self) -> Option<(Slot, usize)> {
        self.on.then_some((Slot::Pol, POL_STRIDE * 4))
    }

    /// Each identity's angle, and the area and force its propulsion reads next.
    fn sync(&self, rows: &[f32], host: Host<'_>) -> Result<(), String> {
        let mut theta = angles(host.terms);
        for (row, &id) in rows.chunks_exact(POL_STRIDE).zip(host.ids) {
            theta[id] = f64::from(row[0]);
            let mut last = mechanics::CellState::default();
            last.area = f64::from(row[4]);
            last.force = mechanics::Vector2::new(f64::from(row[5]), f64::from(row[6]));
            host.terms.set_last_evaluation(id, last);
        }
        host.terms.set_variable("polarity/theta", &theta)
    }

    /// The stiffness `J |t|` the update kept in the slot's word 2.
    fn unstable(&self, code: u32, rows: &[f32], slot: usize) -> Option<(&'static str, f64)> {
        (code == UNSTABLE).then(|| ("polarity", f64::from(rows[slot * POL_STRIDE + 2])))
    }

    /// The force pass reads 4 floats a cell, and the update up to 11 and writes up to 7.
    fn traffic(&self) -> Traffic {
        Traffic {
            patch_node: 0.0,
            lattice_node: 0.0,
            cell: 88.0,
        }
    }
}
