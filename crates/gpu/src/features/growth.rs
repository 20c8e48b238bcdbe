//! The division clock's growth phase: each slot's growth start, from which the kernels scale
//! a growing cell's target area (`wgsl/growth.wgsl`). The clock itself, and the divisions,
//! run on the host.

use super::{Dims, Feature, View};
use crate::bindings::Slot;
use crate::shared::{Kinds, Params};

/// The growth phase on the device.
pub(crate) struct Growth {
    on: bool,
    /// The model time the growth starts are measured from (the last upload's).
    origin: f64,
}

impl Growth {
    pub fn new(on: bool) -> Self {
        Self { on, origin: 0.0 }
    }
}

impl Feature for Growth {
    fn wgsl(&self) -> &'static str {
        include_str!("../wgsl/growth.wgsl")
    }

    fn constant(&self) -> &'static str {
        "GROWTH"
    }

    fn on(&self) -> bool {
        self.on
    }

    fn buffers(&self, dims: Dims) -> Vec<(Slot, u64)> {
        vec![(Slot::Growth, dims.cells * 4)]
    }

    /// `T_g`, and the time of the device's state at its last sync or upload less the
    /// growth's origin.
    fn uniforms(&self, view: &View<'_>, params: &mut Params, _kinds: &mut Kinds) {
        params.growth_time = view.proliferation.map_or(0.0, |c| c.growth_time as f32);
        params.growth_now = (view.base.1 - self.origin) as f32;
    }

    /// Each slot's growth start (its birth plus its cycle, from the clock's lineage), from
    /// this upload's time, which the steps' times are counted from.
    fn data(&mut self, view: &View<'_>, upload: bool) -> Vec<(Slot, Vec<u8>)> {
        if !upload {
            return Vec::new();
        }
        self.origin = view.time;
        let Some(clock) = view.proliferation.filter(|_| self.on) else {
            return Vec::new();
        };
        let starts: Vec<f32> = view
            .ids
            .iter()
            .map(|&id| {
                clock
                    .growth_start(id)
                    .map_or(f32::INFINITY, |g| (g - self.origin) as f32)
            })
            .collect();
        vec![(Slot::Growth, bytemuck::cast_slice(&starts).to_vec())]
    }
}
