//! Walls: a static lattice field `(w, ∇²w)` per node that the lattice pass adds to the
//! pressure and the force pass to each cell's derivative (`wgsl/walls.wgsl`), with the
//! coefficients `2κ_w/λ` and `2ω_wλ` ([`mechanics::equations::wall_coefficients`]).

use super::{Dims, Feature, Traffic, View};
use crate::bindings::Slot;
use crate::shared::{Kinds, Params};

/// The walls on the device.
pub(crate) struct Walls {
    on: bool,
    /// Which field the device holds: the address of the tissue's in effect, or `None`.
    uploaded: Option<usize>,
}

impl Walls {
    pub fn new(on: bool) -> Self {
        Self { on, uploaded: None }
    }
}

impl Feature for Walls {
    fn wgsl(&self) -> &'static str {
        include_str!("../wgsl/walls.wgsl")
    }

    fn constant(&self) -> &'static str {
        "WALLS"
    }

    fn on(&self) -> bool {
        self.on
    }

    fn buffers(&self, dims: Dims) -> Vec<(Slot, u64)> {
        vec![(Slot::Wall, dims.nodes * 8)]
    }

    fn uniforms(&self, view: &View<'_>, params: &mut Params, _kinds: &mut Kinds) {
        let [repulsion, adhesion] = match (view.walls, view.wall_field) {
            (Some(w), Some(_)) => {
                mechanics::equations::wall_coefficients(w.kappa, w.omega, view.params.energy.lambda)
            }
            _ => [0.0; 2],
        };
        params.wall_repulsion = repulsion as f32;
        params.wall_adhesion = adhesion as f32;
    }

    /// The field in effect, whenever it is not the one on the device (a wound opens when the
    /// activity starts).
    fn data(&mut self, view: &View<'_>, _upload: bool) -> Vec<(Slot, Vec<u8>)> {
        let field = view.wall_field;
        let key = field.map(|f| f as *const phasefield::WallField as usize);
        if key == self.uploaded {
            return Vec::new();
        }
        self.uploaded = key;
        match field {
            Some(f) if self.on => {
                let values: Vec<[f32; 2]> = f
                    .w()
                    .iter()
                    .zip(f.laplacian())
                    .map(|(&w, &l)| [w as f32, l as f32])
                    .collect();
                vec![(Slot::Wall, bytemuck::cast_slice(&values).to_vec())]
            }
            _ => Vec::new(),
        }
    }

    /// The force pass reads `(w, ∇²w)` at each patch node, the lattice pass at each node.
    fn traffic(&self) -> Traffic {
        Traffic {
            patch_node: 8.0,
            lattice_node: 8.0,
            cell: 0.0,
        }
    }
}
