//! One kind of rule for every verdict (issue 54): a claim about an effect, the smallest effect
//! that counts, and three outcomes that exclude each other.
//!
//! A figure measures an effect `e` with a standard error `s` (over seeds, or from a fit), signed
//! so that the claim's direction is positive. With `z = 2` standard errors and the smallest
//! effect that counts `δ > 0`, a claim that **the effect is there** ([`Claim::Effect`]: "defects
//! self-propel", "extrusions concentrate at defects") reads
//! - *holds* when the effect is resolved and at least that size: `e − z s > 0` and `e ≥ δ`;
//! - *does not hold* when it is resolved below that size: `e + z s < δ` (which includes a
//!   resolved effect of the wrong sign, and an equivalence to zero within `δ`);
//! - *inconclusive* otherwise.
//!
//! A claim that **there is no such effect** ([`Claim::Absence`]: "the threshold does not move
//! with the box", "no net flow") is the same test on `|e|` with the outcomes swapped: it holds
//! when `|e| + z s < δ` and does not hold when `|e| − z s > 0` and `|e| ≥ δ`.
//!
//! The two outcomes exclude each other: "holds" of an effect needs `e ≥ δ`, "does not hold"
//! needs `e < δ − z s ≤ δ`. An estimate or error that is not finite, a negative error, or a
//! `δ` that is not positive is inconclusive. `proptest` checks the exclusion over estimates,
//! errors, sizes and both kinds.

use super::{g, Verdict};

/// What a claim says of its effect.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Claim {
    /// The effect is there, at least the smallest size, in the positive direction.
    Effect,
    /// There is no effect as large as the smallest size, either way.
    Absence,
}

/// A claim's rule: the effect, the smallest size that counts, and how many standard errors
/// resolve it.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Rule {
    /// What the effect is, in words with its units ("d − d_random, towards the defect (nodes)").
    pub effect: String,
    /// The smallest effect that counts, `δ > 0`, in the estimate's units.
    pub smallest: f64,
    /// What the claim says of it.
    pub claim: Claim,
    /// Standard errors that resolve an effect (2).
    pub z: f64,
}

/// The outcome of a rule: the verdict and the statistic in words (the estimate, its error,
/// the smallest effect and which inequality decided).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Outcome {
    pub verdict: Verdict,
    pub why: String,
}

impl Rule {
    /// The rule of a claim that an effect is there, at least `smallest` in size.
    pub fn effect(effect: impl Into<String>, smallest: f64) -> Self {
        Self {
            effect: effect.into(),
            smallest,
            claim: Claim::Effect,
            z: 2.0,
        }
    }

    /// The rule of a claim that there is no effect as large as `smallest`, either way.
    pub fn absence(effect: impl Into<String>, smallest: f64) -> Self {
        Self {
            effect: effect.into(),
            smallest,
            claim: Claim::Absence,
            z: 2.0,
        }
    }

    /// Whether the inputs can decide anything.
    fn decidable(&self, e: f64, s: f64) -> bool {
        e.is_finite() && s.is_finite() && s >= 0.0 && self.smallest > 0.0 && self.z > 0.0
    }

    /// Whether the effect is resolved (`|e| − z s > 0` in its direction) and at least the
    /// smallest size: `x` is `e` for an effect, `|e|` for an absence.
    fn present(&self, x: f64, s: f64) -> bool {
        x - self.z * s > 0.0 && x >= self.smallest
    }

    /// Whether the effect is resolved below the smallest size.
    fn below(&self, x: f64, s: f64) -> bool {
        x + self.z * s < self.smallest
    }

    /// The effect as the test reads it: signed for an effect, its size for an absence.
    fn read(&self, e: f64) -> f64 {
        match self.claim {
            Claim::Effect => e,
            Claim::Absence => e.abs(),
        }
    }

    /// Whether the claim holds on `e ± s`.
    pub fn holds(&self, e: f64, s: f64) -> bool {
        let x = self.read(e);
        self.decidable(e, s)
            && match self.claim {
                Claim::Effect => self.present(x, s),
                Claim::Absence => self.below(x, s),
            }
    }

    /// Whether the claim does not hold on `e ± s`.
    pub fn fails(&self, e: f64, s: f64) -> bool {
        let x = self.read(e);
        self.decidable(e, s)
            && match self.claim {
                Claim::Effect => self.below(x, s),
                Claim::Absence => self.present(x, s),
            }
    }

    /// The verdict on `e ± s`, with the statistic and the inequality that decided.
    pub fn decide(&self, e: f64, s: f64) -> Outcome {
        let (z, d) = (self.z, self.smallest);
        let what = format!(
            "{} = {} ± {} (s.e.); smallest effect that counts {}",
            self.effect,
            g(e),
            g(s),
            g(d)
        );
        let (verdict, rule) = if !self.decidable(e, s) {
            (Verdict::Inconclusive, "not measured".to_string())
        } else if self.holds(e, s) {
            let r = match self.claim {
                Claim::Effect => format!("resolved by {z} s.e. and at least {}", g(d)),
                Claim::Absence => format!("below {} by {z} s.e.", g(d)),
            };
            (Verdict::Holds, r)
        } else if self.fails(e, s) {
            let r = match self.claim {
                Claim::Effect => format!("below {} by {z} s.e.", g(d)),
                Claim::Absence => format!("resolved by {z} s.e. and at least {}", g(d)),
            };
            (Verdict::DoesNotHold, r)
        } else {
            (
                Verdict::Inconclusive,
                format!("neither resolved at {} nor below it by {z} s.e.", g(d)),
            )
        };
        Outcome {
            verdict,
            why: format!("{what}: {rule}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn any_value() -> impl Strategy<Value = f64> {
        prop_oneof![
            8 => -10.0..10.0f64,
            1 => Just(0.0),
            1 => Just(f64::NAN),
            1 => Just(f64::INFINITY),
            1 => Just(-1.0),
        ]
    }

    proptest! {
        /// For every rule (both kinds, any size and resolution) and every estimate and error,
        /// exactly one outcome is true, and `decide` gives it.
        #[test]
        fn exactly_one_outcome(
            e in any_value(),
            s in any_value(),
            d in prop_oneof![4 => 0.001..5.0f64, 1 => Just(0.0), 1 => Just(-1.0)],
            z in prop_oneof![4 => 0.5..4.0f64, 1 => Just(2.0)],
            absence in any::<bool>(),
        ) {
            let mut rule = if absence { Rule::absence("x", d) } else { Rule::effect("x", d) };
            rule.z = z;
            let (h, f) = (rule.holds(e, s), rule.fails(e, s));
            let i = !h && !f;
            prop_assert_eq!(u8::from(h) + u8::from(f) + u8::from(i), 1, "e {} s {} d {}", e, s, d);
            let want = if h { Verdict::Holds } else if f { Verdict::DoesNotHold } else { Verdict::Inconclusive };
            prop_assert_eq!(rule.decide(e, s).verdict, want);
        }
    }

    /// Each outcome of an effect, on numbers where the answer is plain.
    #[test]
    fn an_effect_reads_each_outcome() {
        let r = Rule::effect("closer than random (nodes)", 2.0);
        assert_eq!(r.decide(4.0, 0.5).verdict, Verdict::Holds);
        // Resolved, but smaller than what counts: it does not hold (an equivalence).
        assert_eq!(r.decide(0.28, 0.14).verdict, Verdict::DoesNotHold);
        // The wrong sign, resolved.
        assert_eq!(r.decide(-3.0, 0.5).verdict, Verdict::DoesNotHold);
        // Large but not resolved; resolved but its interval reaches δ.
        assert_eq!(r.decide(3.0, 2.0).verdict, Verdict::Inconclusive);
        assert_eq!(r.decide(1.5, 0.5).verdict, Verdict::Inconclusive);
        assert_eq!(r.decide(f64::NAN, 0.5).verdict, Verdict::Inconclusive);
        assert!(r.decide(0.28, 0.14).why.contains("below 2.00 by 2 s.e."));
    }

    /// Each outcome of an absence.
    #[test]
    fn an_absence_reads_each_outcome() {
        let r = Rule::absence("drift (nodes/TU)", 0.1);
        assert_eq!(r.decide(0.01, 0.02).verdict, Verdict::Holds);
        assert_eq!(r.decide(-0.01, 0.02).verdict, Verdict::Holds);
        assert_eq!(r.decide(-0.5, 0.1).verdict, Verdict::DoesNotHold);
        assert_eq!(r.decide(0.05, 0.1).verdict, Verdict::Inconclusive);
        assert_eq!(r.decide(0.5, 1.0).verdict, Verdict::Inconclusive);
    }
}
