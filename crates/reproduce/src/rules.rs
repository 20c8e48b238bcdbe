//! Verdict rules shared by figures: each takes measured values with their errors and returns
//! a verdict that can come out each way, with the statistic in words. Each rule is unit-tested
//! on synthetic data for every outcome.

use stability::fit;

use super::rule::{Outcome, Rule};
use super::{g, Verdict};

/// The smallest relative effect that counts in the threshold's rules: 10 % of ζ_cr (a
/// difference between methods, boxes or run lengths, an intercept of ζ_cr(γ)).
pub(crate) const TENTH: f64 = 0.1;

/// The rule of an absence on a relative effect with [`TENTH`] counting.
fn tenth(effect: &str) -> Rule {
    Rule::absence(effect, TENTH)
}

/// Agreement of the two methods: for each configuration measured by both, the rule of an
/// absence on `(ζ_growth − ζ_arnoldi)/ζ_arnoldi` (error `√(e_g² + e_a²)/ζ_arnoldi`) with 10 %
/// counting. Holds when every pair holds, does not hold when one does not, inconclusive
/// otherwise.
pub(crate) fn rule_agree(pairs: &[(f64, f64, f64, f64)]) -> (Verdict, String) {
    if pairs.is_empty() {
        return (
            Verdict::Inconclusive,
            "no configuration was measured by both methods".into(),
        );
    }
    let rule = tenth("(ζ_growth − ζ_arnoldi)/ζ_arnoldi");
    let outcomes: Vec<Outcome> = pairs
        .iter()
        .map(|&(za, ea, zg, eg)| rule.decide((zg - za) / za, ea.hypot(eg) / za.abs()))
        .collect();
    all_of(&outcomes)
}

/// One verdict from several: does not hold when one does not, holds when there is at least one
/// and all hold, inconclusive otherwise.
pub(crate) fn all_hold(verdicts: impl IntoIterator<Item = Verdict>) -> Verdict {
    let (mut any, mut all_hold) = (false, true);
    for v in verdicts {
        if v == Verdict::DoesNotHold {
            return Verdict::DoesNotHold;
        }
        any = true;
        all_hold &= v == Verdict::Holds;
    }
    if any && all_hold {
        Verdict::Holds
    } else {
        Verdict::Inconclusive
    }
}

/// One verdict from several, when one is enough: holds when one holds, does not hold when
/// there is at least one and none holds and all do not hold, inconclusive otherwise (the
/// outcome of a claim that one point of a scan shows an effect).
pub(crate) fn any_holds(verdicts: impl IntoIterator<Item = Verdict>) -> Verdict {
    // The dual of `all_hold`: swap holds and does not hold on the way in and out.
    let swap = |v: Verdict| match v {
        Verdict::Holds => Verdict::DoesNotHold,
        Verdict::DoesNotHold => Verdict::Holds,
        Verdict::Inconclusive => Verdict::Inconclusive,
    };
    swap(all_hold(verdicts.into_iter().map(swap)))
}

/// Several outcomes of one rule as one verdict ([`all_hold`]), with the reason that decided:
/// the first that does not hold, the first undecided one, or the first (with the count) when
/// all hold.
pub(crate) fn all_of(outcomes: &[Outcome]) -> (Verdict, String) {
    let v = all_hold(outcomes.iter().map(|o| o.verdict));
    let why = match (v, outcomes.first()) {
        (Verdict::Holds, Some(o)) => format!("all {} hold; first: {}", outcomes.len(), o.why),
        (_, None) => "nothing was measured".into(),
        _ => outcomes
            .iter()
            .find(|o| o.verdict == v)
            .map_or_else(String::new, |o| o.why.clone()),
    };
    (v, why)
}

/// Linearity in γ: a weighted parabola through the points. Its bend is the curvature's
/// departure from the line at the ends of the range, `c₂ (Δγ/2)²`, as a fraction of the change
/// of ζ_cr over the range; by the rule of an absence with 5 % counting: a law `ζ_cr ∝ γ²` over
/// γ = 0.006–0.014 bends by 10 % of its change, `∝ √γ` by −5 % (inconclusive with fewer than
/// four points: a parabola through three leaves no residual).
pub(crate) fn rule_linear(x: &[f64], y: &[f64], e: &[f64]) -> (Verdict, String) {
    if x.len() < 4 {
        return (
            Verdict::Inconclusive,
            format!(
                "{} values of γ: a parabola needs four to leave a residual",
                x.len()
            ),
        );
    }
    let Some(f) = fit::poly(x, y, Some(e), 2) else {
        return (Verdict::Inconclusive, "the fit is singular".into());
    };
    let span = x.iter().copied().fold(f64::NEG_INFINITY, f64::max)
        - x.iter().copied().fold(f64::INFINITY, f64::min);
    let change = (y.iter().copied().fold(f64::NEG_INFINITY, f64::max)
        - y.iter().copied().fold(f64::INFINITY, f64::min))
    .max(1e-300);
    let scale = (span / 2.0).powi(2) / change;
    let o = Rule::absence("bend c₂(Δγ/2)² / change of ζ_cr", 0.05)
        .decide(f.coef[2] * scale, f.se[2] * scale);
    (
        o.verdict,
        format!(
            "curvature c₂ = {} ± {}: {}",
            g(f.coef[2]),
            g(f.se[2]),
            o.why
        ),
    )
}

/// Proportionality `ζ_cr = aγ`: the weighted line's intercept `b ± se` relative to ζ_cr at
/// the middle γ, by the rule of an absence with 10 % counting.
pub(crate) fn rule_proportional(x: &[f64], y: &[f64], e: &[f64]) -> (Verdict, String) {
    let Some(f) = fit::line(x, y, Some(e)) else {
        return (Verdict::Inconclusive, "fewer than two values of γ".into());
    };
    let mid = x.iter().sum::<f64>() / x.len() as f64;
    let z_mid = f.coef[0] + f.coef[1] * mid;
    let (b, se) = (f.coef[0], f.se[0]);
    let o = tenth("intercept / ζ_cr(middle γ)").decide(b / z_mid, se / z_mid.abs());
    (
        o.verdict,
        format!(
            "intercept {} ± {}, slope {} ± {}, ζ_cr = {} at γ = {}: {}",
            g(b),
            g(se),
            g(f.coef[1]),
            g(f.se[1]),
            g(z_mid),
            g(mid),
            o.why
        ),
    )
}

/// Independence of the box: the difference Δ between ζ_cr on the largest and the smallest box,
/// with its error, relative to their mean, by the rule of an absence with 10 % counting.
pub(crate) fn rule_box(points: &[(f64, f64, f64)]) -> (Verdict, String) {
    if points.len() < 2 {
        return (Verdict::Inconclusive, "one box size".into());
    }
    let mut p = points.to_vec();
    p.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (s, l) = (p[0], p[p.len() - 1]);
    let d = l.1 - s.1;
    let e = s.2.hypot(l.2);
    let z = 0.5 * (s.1 + l.1);
    let o =
        tenth(&format!("(ζ_cr(L = {}) − ζ_cr(L = {}))/ζ_cr", l.0, s.0)).decide(d / z, e / z.abs());
    (o.verdict, format!("Δ = {} ± {}: {}", g(d), g(e), o.why))
}

/// The continuum prediction `ζ_cr → 0` as `L → ∞`, from ζ_cr on exact tilings of one box
/// (`(L, ζ_cr, error)`), compared across fit forms: `ζ_cr = ζ_∞ + c L^(−p)` for p = 2 (the
/// slowest elastic mode of a box, `q² ∝ 1/L²`), 1 and ½, weighted; a form fits when its χ² is
/// below its 99 % point. The spread of ζ_∞ between the forms that fit is part of the error.
/// Holds when every form that fits has `ζ_∞ < 2 se(ζ_∞)` and a fall `c > 2 se(c)` (the limit is
/// not positive); does not hold when every form that fits has `ζ_∞ − 2 se(ζ_∞) > 0` (a finite
/// limit whatever the form); inconclusive when the forms disagree, when none fits, and with
/// fewer than four sizes (three points fit every two-parameter form: the referee's point on
/// the interaction form's limit).
pub(crate) fn rule_continuum(points: &[(f64, f64, f64)]) -> (Verdict, String) {
    if points.len() < 4 {
        return (
            Verdict::Inconclusive,
            format!(
                "{} box sizes: a limit L → ∞ needs four exact tilings (three points fit every two-parameter form)",
                points.len()
            ),
        );
    }
    let y: Vec<f64> = points.iter().map(|p| p.1).collect();
    let e: Vec<f64> = points.iter().map(|p| p.2).collect();
    let mut fitting = Vec::new();
    let mut text = Vec::new();
    for power in [2.0, 1.0, 0.5] {
        let x: Vec<f64> = points.iter().map(|p| p.0.powf(-power)).collect();
        let Some(f) = fit::line(&x, &y, Some(&e)) else {
            continue;
        };
        let fits = f.chi2 <= super::run_length::chi2_99(f.dof);
        text.push(format!(
            "L^(−{power}): ζ_∞ = {} ± {}, χ² = {} for {} dof{}",
            g(f.coef[0]),
            g(f.se[0]),
            g(f.chi2),
            f.dof,
            if fits { "" } else { " (does not fit)" }
        ));
        if fits {
            fitting.push(f);
        }
    }
    let what = text.join("; ");
    if fitting.is_empty() {
        return (
            Verdict::Inconclusive,
            format!("{what}: no form fits the points, so no limit is measured"),
        );
    }
    let lo = fitting
        .iter()
        .map(|f| f.coef[0] - 2.0 * f.se[0])
        .fold(f64::INFINITY, f64::min);
    let hi = fitting
        .iter()
        .map(|f| f.coef[0] + 2.0 * f.se[0])
        .fold(f64::NEG_INFINITY, f64::max);
    let what = format!(
        "{what}; over the forms that fit, ζ_∞ within [{}, {}] (two errors and the spread between forms)",
        g(lo),
        g(hi)
    );
    if lo > 0.0 {
        (Verdict::DoesNotHold, format!("{what}: a finite limit"))
    } else if fitting
        .iter()
        .all(|f| f.coef[0] < 2.0 * f.se[0] && f.coef[1] > 2.0 * f.se[1])
    {
        (Verdict::Holds, what)
    } else {
        (Verdict::Inconclusive, what)
    }
}

/// A threshold that has settled with the run length: the paired per-seed differences
/// `ζ_cr(T) − ζ_cr(T/2)`, mean ± s.e., relative to ζ_cr, by the rule of an absence with 10 %
/// counting (inconclusive with fewer than two seeds).
pub(crate) fn rule_converged(diffs: &[f64], zeta: f64) -> (Verdict, String) {
    if diffs.len() < 2 {
        return (
            Verdict::Inconclusive,
            format!(
                "{} seeds with ζ_cr bracketed at both T and T/2",
                diffs.len()
            ),
        );
    }
    let (m, se) = super::mean_se(diffs);
    let o = tenth("(ζ_cr(T) − ζ_cr(T/2))/ζ_cr").decide(m / zeta, se / zeta.abs());
    (o.verdict, format!("{} seeds: {}", diffs.len(), o.why))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `any_holds` on every list of up to three verdicts, against its statement: holds when one
    /// holds, does not hold when there is one and every one does not, inconclusive otherwise.
    #[test]
    fn any_holds_holds_when_one_holds() {
        use Verdict::*;
        let all = [Holds, DoesNotHold, Inconclusive];
        let mut lists: Vec<Vec<Verdict>> = vec![vec![]];
        for n in 1..=3 {
            let mut next = Vec::new();
            for l in lists.iter().filter(|l| l.len() == n - 1) {
                for v in all {
                    let mut m = l.clone();
                    m.push(v);
                    next.push(m);
                }
            }
            lists.extend(next);
        }
        for l in &lists {
            let want = if l.contains(&Holds) {
                Holds
            } else if !l.is_empty() && l.iter().all(|&v| v == DoesNotHold) {
                DoesNotHold
            } else {
                Inconclusive
            };
            assert_eq!(any_holds(l.iter().copied()), want, "{l:?}");
        }
        assert_eq!(any_holds([Inconclusive, Holds]), Holds);
        assert_eq!(any_holds([DoesNotHold, DoesNotHold]), DoesNotHold);
        assert_eq!(any_holds([]), Inconclusive);
    }

    #[test]
    fn agreement_rule_gives_each_outcome() {
        assert_eq!(rule_agree(&[(1e-3, 2e-5, 1.02e-3, 3e-5)]).0, Verdict::Holds);
        assert_eq!(
            rule_agree(&[(1e-3, 2e-5, 1.5e-3, 3e-5)]).0,
            Verdict::DoesNotHold
        );
        // Within 2 % with tiny errors: an equivalence, holds.
        assert_eq!(rule_agree(&[(1e-3, 1e-6, 1.02e-3, 1e-6)]).0, Verdict::Holds);
        // 5 % apart with 14 % errors: not decided.
        assert_eq!(
            rule_agree(&[(1e-3, 1e-4, 1.05e-3, 1e-4)]).0,
            Verdict::Inconclusive
        );
        // One pair of two apart: the whole does not hold.
        assert_eq!(
            rule_agree(&[(1e-3, 1e-6, 1.0e-3, 1e-6), (1e-3, 2e-5, 1.5e-3, 3e-5)]).0,
            Verdict::DoesNotHold
        );
        assert_eq!(rule_agree(&[]).0, Verdict::Inconclusive);
    }

    #[test]
    fn linearity_rule_gives_each_outcome() {
        let x = [0.006, 0.008, 0.01, 0.012, 0.014];
        let e = [1e-5; 5];
        let line: Vec<f64> = x.iter().map(|g| 2e-4 + 0.1 * g).collect();
        assert_eq!(rule_linear(&x, &line, &e).0, Verdict::Holds);
        let bent: Vec<f64> = x.iter().map(|g| 2e-4 + 0.1 * g + 40.0 * g * g).collect();
        assert_eq!(rule_linear(&x, &bent, &e).0, Verdict::DoesNotHold);
        // Errors as large as the whole trend: too weak to tell.
        assert_eq!(rule_linear(&x, &line, &[4e-4; 5]).0, Verdict::Inconclusive);
        assert_eq!(
            rule_linear(&x[..3], &line[..3], &e[..3]).0,
            Verdict::Inconclusive
        );
    }

    #[test]
    fn proportionality_rule_gives_each_outcome() {
        let x = [0.006, 0.008, 0.01, 0.012, 0.014];
        let e = [1e-5; 5];
        let through_zero: Vec<f64> = x.iter().map(|g| 0.1 * g).collect();
        assert_eq!(rule_proportional(&x, &through_zero, &e).0, Verdict::Holds);
        let offset: Vec<f64> = x.iter().map(|g| 5e-4 + 0.05 * g).collect();
        assert_eq!(rule_proportional(&x, &offset, &e).0, Verdict::DoesNotHold);
        assert_eq!(
            rule_proportional(&x, &through_zero, &[5e-4; 5]).0,
            Verdict::Inconclusive
        );
    }

    #[test]
    fn box_rule_gives_each_outcome() {
        assert_eq!(
            rule_box(&[(83.0, 1e-3, 1e-5), (333.0, 1.01e-3, 1e-5)]).0,
            Verdict::Holds
        );
        assert_eq!(
            rule_box(&[(83.0, 1e-3, 1e-5), (333.0, 5e-4, 1e-5)]).0,
            Verdict::DoesNotHold
        );
        assert_eq!(
            rule_box(&[(83.0, 1e-3, 1e-4), (333.0, 1.1e-3, 1e-4)]).0,
            Verdict::Inconclusive
        );
        assert_eq!(rule_box(&[(83.0, 1e-3, 1e-5)]).0, Verdict::Inconclusive);
    }

    #[test]
    fn continuum_rule_gives_each_outcome() {
        // Four exact tilings of the 83 × 120 box.
        let l = [83.0, 166.0, 249.0, 332.0];
        let to_zero: Vec<(f64, f64, f64)> = l.iter().map(|&l| (l, 4.0 / (l * l), 1e-6)).collect();
        assert_eq!(rule_continuum(&to_zero).0, Verdict::Holds);
        let finite: Vec<(f64, f64, f64)> =
            l.iter().map(|&l| (l, 5e-4 + 4.0 / (l * l), 1e-6)).collect();
        assert_eq!(rule_continuum(&finite).0, Verdict::DoesNotHold);
        // Three sizes: every form fits, no verdict.
        assert_eq!(rule_continuum(&finite[..3]).0, Verdict::Inconclusive);
        let noisy: Vec<(f64, f64, f64)> = l.iter().map(|&l| (l, 4.0 / (l * l), 1e-3)).collect();
        assert_eq!(rule_continuum(&noisy).0, Verdict::Inconclusive);
        // Linear in ln L, reaching zero near L = 840 (the measured shape of the paper form):
        // the forms that fit put the limit at or below zero, never positive.
        let log: Vec<(f64, f64, f64)> = l
            .iter()
            .map(|&l: &f64| (l, 1.66e-3 - 2.465e-4 * l.ln(), 1.5e-5))
            .collect();
        let (v, why) = rule_continuum(&log);
        assert_ne!(v, Verdict::DoesNotHold, "{why}");
        // A law in 1/L with a positive limit, measured loosely: the 1/L² and 1/L forms both
        // fit, one limit above zero and one not: the forms disagree.
        let loose: Vec<(f64, f64, f64)> = l.iter().map(|&l| (l, 1e-4 + 0.03 / l, 1.2e-5)).collect();
        let (v, why) = rule_continuum(&loose);
        eprintln!("{why}");
        assert_eq!(v, Verdict::Inconclusive, "{why}");
    }

    #[test]
    fn convergence_rule_gives_each_outcome() {
        assert_eq!(rule_converged(&[1e-5, -1e-5, 2e-5], 2e-3).0, Verdict::Holds);
        assert_eq!(
            rule_converged(&[-7e-4, -6e-4, -8e-4], 2e-3).0,
            Verdict::DoesNotHold
        );
        assert_eq!(
            rule_converged(&[-7e-4, 6e-4, 1e-4], 2e-3).0,
            Verdict::Inconclusive
        );
        assert_eq!(rule_converged(&[1e-5], 2e-3).0, Verdict::Inconclusive);
    }
}
