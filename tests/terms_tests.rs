//! The physics terms in whole scenes (docs/model.md §11): the shipped mixture scene, where the
//! soft cells must take the shapes the stiff ones leave them.

use mechanics::Workspace;
use scene::Scene;

/// T6.2 of the extensions: `scenes/mixture.toml` (24 stiff cells with γ = 0.05 and 24 soft
/// ones with γ = 0.005, no activity) for 150 TU: the soft cells' mean deformation `|S_i|`
/// exceeds the stiff cells' by more than 1.5× (the extensions' expectation; measured 3.1× at
/// 150 TU and 5.8× at 450 TU), and the soft cells are larger (their interfaces cost less).
#[test]
fn soft_cells_deform_more_than_stiff_ones() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenes/mixture.toml"
    ))
    .unwrap();
    let scene = Scene::parse(&text, &["run.time=150".into()]).unwrap();
    let mut sim = scene.simulation::<f32>().unwrap();
    sim.run().unwrap();
    let (tissue, mut ws): (_, Workspace<f32>) = sim.into_parts();
    tissue.observe(&mut ws);
    let pops = tissue.populations();
    let (mut s, mut a, mut n) = ([0.0; 2], [0.0; 2], [0.0; 2]);
    for (slot, c) in ws.cell_states().iter().enumerate() {
        let k = pops.population(tissue.cell_ids()[slot]);
        s[k] += c.shape.magnitude();
        a[k] += c.area;
        n[k] += 1.0;
    }
    let (stiff, soft) = (s[0] / n[0], s[1] / n[1]);
    assert_eq!(n, [24.0, 24.0]);
    assert!(soft > 1.5 * stiff, "soft |S| {soft} against stiff {stiff}");
    assert!(a[1] / n[1] > a[0] / n[0], "areas {a:?}");
}
