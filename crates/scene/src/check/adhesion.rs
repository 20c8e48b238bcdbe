//! The check of `[adhesion]`.

use crate::error::{invalid, SceneError};
use crate::file::SceneFile;

/// `[adhesion]`: ω in range, below γ; `pairs` a symmetric matrix over the populations, each
/// ω_pq below the γ of both populations.
pub(crate) fn adhesion(file: &SceneFile) -> Result<(), SceneError> {
    if let Some(a) = &file.adhesion {
        if let Some(rows) = &a.pairs {
            return pairs(file, a.omega, rows);
        }
        if !(a.omega.is_finite() && a.omega >= 0.0) {
            return Err(invalid(
                "adhesion",
                "omega",
                a.omega,
                "the adhesion strength must be zero or positive",
                "use a value of order 0.01 (the reference code's cluster example), or remove [adhesion]",
            ));
        }
        // Two overlapping cells have the gradient energy λ(γ ± ω)|∇(φ1 ± φ2)|²/2: at ω ≥ γ
        // their difference costs nothing and a contact breaks into stripes of the lattice.
        let gamma = file
            .population
            .iter()
            .filter_map(|p| p.gamma)
            .fold(file.model.gamma, f64::min);
        if a.omega >= gamma {
            return Err(invalid(
                "adhesion",
                "omega",
                a.omega,
                format!("adhesion at or above the interface stiffness (gamma = {gamma}) makes the interface between two cells cost nothing, and contacts break into stripes at the lattice scale"),
                format!("use omega below gamma, e.g. {}", gamma * 0.75),
            ));
        }
    }
    Ok(())
}

/// `[adhesion] pairs`: a pair matrix ([`pair_matrix`]) with each ω_pq below min(γ_p, γ_q)
/// (the single ω's limit for the two cells of the pair); not with `omega`.
fn pairs(file: &SceneFile, omega: f64, rows: &[Vec<f64>]) -> Result<(), SceneError> {
    if omega != 0.0 {
        return Err(invalid(
            "adhesion",
            "pairs",
            format!("{rows:?}"),
            "`pairs` gives the adhesion of every pair of populations, and `omega` one for every pair: only one can hold",
            "remove `omega` (or set it to 0), or remove `pairs`",
        ));
    }
    let gamma = |p: usize| file.population[p].gamma.unwrap_or(file.model.gamma);
    pair_matrix(
        file,
        "adhesion",
        "ω",
        rows,
        "use values of order 0.01 or 0",
        |p, q, w| {
            let limit = gamma(p).min(gamma(q));
            (w >= limit).then(|| {
            (
                format!("at or above the interface stiffness of its cells (gamma = {limit}): their shared interface would cost nothing, and contacts break into stripes at the lattice scale"),
                format!("use a value below {limit}, e.g. {}", limit * 0.75),
            )
        })
        },
    )
}

/// `[repulsion]`: `pairs`, a pair matrix ([`pair_matrix`]) of κ_pq; the time step's stability
/// takes the largest entry (`validate::stability_estimate`).
pub(crate) fn repulsion(file: &SceneFile) -> Result<(), SceneError> {
    let Some(r) = &file.repulsion else {
        return Ok(());
    };
    pair_matrix(
        file,
        "repulsion",
        "κ",
        &r.pairs,
        "use values of order 0.1 (the paper's κ) or 0",
        |_, _, _| None,
    )
}

/// A matrix over the populations in `[section] pairs` (symbol `what`): one row per
/// `[[population]]` (in their order), square, symmetric, finite and not negative, and each
/// entry past no limit of its pair (`limit(p, q, value)`: the problem and the fix, if it is
/// past). Errors name the pair (by population names, or A, B, … without) and its row and
/// column.
pub(crate) fn pair_matrix(
    file: &SceneFile,
    section: &'static str,
    what: &str,
    rows: &[Vec<f64>],
    typical: &str,
    limit: impl Fn(usize, usize, f64) -> Option<(String, String)>,
) -> Result<(), SceneError> {
    let n = file.population.len();
    let shown = format!("{rows:?}");
    if n == 0 || rows.len() != n || rows.iter().any(|r| r.len() != n) {
        return Err(invalid(
            section,
            "pairs",
            shown,
            format!("`pairs` needs one row of {n} values for each of the scene's {n} [[population]] tables (in their order)"),
            if n == 0 {
                if section == "adhesion" {
                    "add [[population]] tables, or use `omega` for one adhesion between every pair".to_string()
                } else {
                    "add [[population]] tables, or use [model] kappa for one repulsion between every pair".to_string()
                }
            } else {
                format!("give a {n} × {n} matrix, such as [[a, b], [b, c]] for two populations")
            },
        ));
    }
    let name = |p: usize| {
        file.population[p]
            .name
            .clone()
            .unwrap_or_else(|| ((b'A' + (p % 26) as u8) as char).to_string())
    };
    for p in 0..n {
        for q in 0..n {
            let w = rows[p][q];
            let pair = format!("{}–{}", name(p), name(q));
            if !(w.is_finite() && w >= 0.0) {
                return Err(invalid(
                    section,
                    "pairs",
                    shown,
                    format!("{what} of the pair {pair} (row {}, column {}) is {w}: it must be zero or positive", p + 1, q + 1),
                    typical,
                ));
            }
            if rows[q][p] != w {
                return Err(invalid(
                    section,
                    "pairs",
                    shown,
                    format!("{what} of the pair {pair} is {w} in row {}, column {} but {} in row {}, column {}: the matrix must be symmetric", p + 1, q + 1, rows[q][p], q + 1, p + 1),
                    "give the same value on both sides of the diagonal",
                ));
            }
            if let Some((problem, fix)) = limit(p, q, w) {
                return Err(invalid(
                    section,
                    "pairs",
                    shown,
                    format!("{what} of the pair {pair} is {w}, {problem}"),
                    fix,
                ));
            }
        }
    }
    Ok(())
}
