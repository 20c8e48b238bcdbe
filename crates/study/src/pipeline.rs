//! The glue between the simulation's lattice fields and the analysis of a run.

use analysis::crop::CropFields;
use mechanics::TissueFields;

/// The fields of a state that the defect-centred averages crop.
pub fn crop_fields(f: &TissueFields) -> CropFields<'_> {
    CropFields {
        vx: &f.vx,
        vy: &f.vy,
        sigma_xx: &f.sigma_xx,
        sigma_yy: &f.sigma_yy,
        sigma_xy: &f.sigma_xy,
        pressure: &f.pressure,
        qxx: &f.qxx,
        qxy: &f.qxy,
    }
}
