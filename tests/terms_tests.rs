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

/// `--set population.K.key=value` changes the K-th `[[population]]` table (so that sweeps can
/// vary a population's parameters); a position that is not there, or no position, is an error
/// that says how the tables are numbered.
#[test]
fn a_population_is_set_by_its_position() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenes/mixture.toml"
    ))
    .unwrap();
    let s = Scene::parse(
        &text,
        &["population.1.gamma=0.02".into(), "population.0.xi=3".into()],
    )
    .unwrap();
    let kinds = s.populations();
    assert_eq!(kinds.kinds()[1].gamma, Some(0.02));
    assert_eq!(kinds.kinds()[0].xi, Some(3.0));
    assert_eq!(
        kinds.kinds()[0].gamma,
        Some(0.05),
        "the rest of the table is kept"
    );
    let e = Scene::parse(&text, &["population.2.gamma=0.02".into()])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("2 [[population]] tables, numbered from 0"),
        "{e}"
    );
    let e = Scene::parse(&text, &["population.gamma=0.02".into()])
        .unwrap_err()
        .to_string();
    assert!(e.contains("--set population.0.gamma"), "{e}");
}
