//! `[adhesion] pairs` and `[repulsion] pairs` (issue 49): adhesion and repulsion by pair of
//! populations, checked by pair.

use scene::Scene;

/// Two populations (a, b) of one cell each, with the `[adhesion]` table `adhesion`.
fn parse(adhesion: &str) -> Result<Scene, String> {
    let text = format!(
        "[domain]\nlx = 40\nly = 30\n[cells]\ncount = 2\nradius = 6.0\n[integrator]\nmargin = 12\n[run]\ntime = 1\n\
         [[population]]\nname = \"a\"\ncount = 1\n[[population]]\nname = \"b\"\ncount = 1\ngamma = 0.006\n{adhesion}"
    );
    Scene::parse(&text, &[]).map_err(|e| e.to_string())
}

/// A symmetric matrix below both γ reaches the populations row by row; the errors name the
/// key and the pair, and say what to do.
#[test]
fn pairs_are_checked_by_pair() {
    let s = parse("[adhesion]\npairs = [[0.004, 0.001], [0.001, 0.0]]\n").unwrap();
    assert_eq!(
        s.populations().adhesion(),
        Some(&[0.004, 0.001, 0.001, 0.0][..])
    );
    assert_eq!(s.model_params(0.0).omega, 0.0);
    let err = parse("[adhesion]\npairs = [[0.004, 0.001], [0.002, 0.0]]\n").unwrap_err();
    assert!(
        err.contains("pairs") && err.contains("a–b") && err.contains("symmetric"),
        "{err}"
    );
    // b's γ is 0.006: the pair b–b at 0.007 is at or above it.
    let err = parse("[adhesion]\npairs = [[0.004, 0.0], [0.0, 0.007]]\n").unwrap_err();
    assert!(err.contains("b–b") && err.contains("0.006"), "{err}");
    let err = parse("[adhesion]\npairs = [[0.004, -0.001], [-0.001, 0.0]]\n").unwrap_err();
    assert!(err.contains("a–b") && err.contains("positive"), "{err}");
    let err = parse("[adhesion]\npairs = [[0.004]]\n").unwrap_err();
    assert!(
        err.contains("2 × 2") || err.contains("one row of 2"),
        "{err}"
    );
    let err =
        parse("[adhesion]\nomega = 0.002\npairs = [[0.004, 0.0], [0.0, 0.004]]\n").unwrap_err();
    assert!(err.contains("omega") && err.contains("only one"), "{err}");
    // The uniform key still works alone, with no matrix.
    let s = parse("[adhesion]\nomega = 0.002\n").unwrap();
    assert_eq!(s.populations().adhesion(), None);
    assert_eq!(s.model_params(0.0).omega, 0.002);
}

/// `[repulsion] pairs` (issue 49): a symmetric matrix reaches the populations, and each cell
/// has its population's own κ_pp; the errors name the key and the pair; the time step's
/// stability estimate takes the largest entry, so a κ_ab far above the tissue's refuses the
/// scene's dt, naming it.
#[test]
fn repulsion_pairs_are_checked_by_pair() {
    let s = parse("[repulsion]\npairs = [[0.1, 0.3], [0.3, 0.05]]\n").unwrap();
    let pops = s.populations();
    assert_eq!(pops.repulsion(), Some(&[0.1, 0.3, 0.3, 0.05][..]));
    let base = s.model_params(0.0);
    assert_eq!(pops.params(1, &base).energy.kappa, 0.05);
    assert_eq!(pops.largest_repulsion(1, &base), 0.3);
    let err = parse("[repulsion]\npairs = [[0.1, 0.3], [0.2, 0.05]]\n").unwrap_err();
    assert!(
        err.contains("[repulsion]") && err.contains("a–b") && err.contains("symmetric"),
        "{err}"
    );
    let err = parse("[repulsion]\npairs = [[0.1, -0.3], [-0.3, 0.05]]\n").unwrap_err();
    assert!(err.contains("a–b") && err.contains("positive"), "{err}");
    let err = parse("[repulsion]\npairs = [[0.1]]\n").unwrap_err();
    assert!(err.contains("one row of 2"), "{err}");
    let err = parse("[repulsion]\nkappa = 0.1\n").unwrap_err();
    assert!(err.contains("kappa"), "{err}");
    // 4κ/λ at κ = 30 and λ = 3 is 40 of stiffness: dt = 0.2 is far past 2/40.
    let err = parse("[repulsion]\npairs = [[0.1, 30.0], [30.0, 0.1]]\n").unwrap_err();
    assert!(err.contains("dt"), "{err}");
}
