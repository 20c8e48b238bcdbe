//! Adhesion between cells (ω ≠ 0): s1 and its lattice Laplacian per node, a lattice kernel of
//! its own (`adhesion_lattice`, after the lattice pass) and the coefficient `c = 2ωλ`
//! ([`mechanics::equations::adhesion_coefficient`]; `wgsl/adhesion.wgsl`).

use super::{Dims, Extra, Feature, Hook, Traffic, View};
use crate::bindings::Slot;
use crate::shared::{Kinds, Params};

/// Adhesion on the device.
pub(crate) struct Adhesion {
    on: bool,
}

impl Adhesion {
    pub fn new(on: bool) -> Self {
        Self { on }
    }
}

impl Feature for Adhesion {
    fn wgsl(&self) -> &'static str {
        include_str!("../wgsl/adhesion.wgsl")
    }

    fn constant(&self) -> &'static str {
        "ADHESION"
    }

    fn on(&self) -> bool {
        self.on
    }

    fn buffers(&self, dims: Dims) -> Vec<(Slot, u64)> {
        vec![
            (Slot::AdhS1, dims.nodes * 4),
            (Slot::AdhLap, dims.nodes * 4),
        ]
    }

    fn kernels(&self) -> &'static [Extra] {
        &[Extra {
            entry: "adhesion_lattice",
            hook: Hook::Lattice,
        }]
    }

    fn uniforms(&self, view: &View<'_>, params: &mut Params, _kinds: &mut Kinds) {
        params.adhesion = mechanics::equations::adhesion_coefficient(
            view.params.omega,
            view.params.energy.lambda,
        ) as f32;
    }

    fn check(&self, view: &View<'_>) -> Result<(), String> {
        if (view.params.omega != 0.0) != self.on {
            return Err(format!(
                "the backend was built {} adhesion, and the tissue's ω is now {}: build a new backend for it",
                if self.on { "with" } else { "without" },
                view.params.omega
            ));
        }
        Ok(())
    }

    /// The force pass reads `∇²s1` at each patch node; the lattice pass writes s1, the
    /// adhesion pass reads it, writes `∇²s1` and reads and writes `P, s2, Q` (44 bytes a node).
    fn traffic(&self) -> Traffic {
        Traffic {
            patch_node: 4.0,
            lattice_node: 44.0,
            cell: 0.0,
        }
    }
}
