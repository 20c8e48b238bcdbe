//! Counter-based random numbers: a normal deviate is a pure function of its key
//! `(seed, cell id, step, stage)`, so that results do not depend on the number of threads or
//! on the order in which cells are visited, a rejected adaptive step draws the same noise
//! again, and a resumed run continues the same sequence without storing a generator's state.
//!
//! The generator is Philox4x32-10 (Salmon, Moraes, Dror & Shaw, "Parallel random numbers:
//! as easy as 1, 2, 3", SC 2011; the generator of cuRAND and Random123), which needs only
//! 32-bit integer arithmetic: the GPU backend draws the same numbers with the same function
//! in WGSL (`gpu`'s `wgsl/polarity.wgsl`), so that both backends give a cell the same noise. It maps a
//! 128-bit counter and a 64-bit key to four 32-bit words through ten rounds of two 32 × 32 →
//! 64-bit products, and passes the BigCrush battery on every one of its outputs.
//!
//! The key is the run's seed. The counter is `(cell, step low word, step high word,
//! stage)`, where the cell and the stage, each a `u64`, are folded to 32 bits (their high
//! word xor their low word): every stage in use (`terms`, `division`, `populations`) and
//! every cell identity below 2³² folds to a distinct word. Two words give a uniform with 53
//! random bits ([`NoiseKey::uniform`]); the other two, each a uniform with 32 bits, give a
//! normal deviate by the Box–Muller transform ([`NoiseKey::normal`], `|N| ≤ 6.8`).
//!
//! (Until 2026-12 the key was hashed by SplitMix64's 64-bit finaliser, which a GPU opened
//! without 64-bit integers cannot compute: every draw changed once with the switch.)

/// The key of one random draw.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct NoiseKey {
    /// The run's seed.
    pub seed: u64,
    /// The cell's identity.
    pub cell: u64,
    /// The step (the iteration the step starts from).
    pub step: u64,
    /// What is drawn within the step: a term's index and the component, or an initial state.
    pub stage: u64,
}

/// Philox4x32's multipliers and key increments (Salmon et al. 2011, Random123's
/// `PHILOX_M4x32_0`, `PHILOX_M4x32_1`, `PHILOX_W32_0`, `PHILOX_W32_1`).
const M0: u32 = 0xD251_1F53;
const M1: u32 = 0xCD9E_8D57;
const W0: u32 = 0x9E37_79B9;
const W1: u32 = 0xBB67_AE85;

/// The high and low words of the 64-bit product `a b`.
#[inline]
fn mul_hi_lo(a: u32, b: u32) -> (u32, u32) {
    let p = u64::from(a) * u64::from(b);
    ((p >> 32) as u32, p as u32)
}

/// Philox4x32-10: four 32-bit words from a 128-bit counter and a 64-bit key, a bijection of
/// the counter for each key (Random123's `philox4x32(ctr, key)` with 10 rounds).
pub fn philox4x32_10(counter: [u32; 4], key: [u32; 2]) -> [u32; 4] {
    let (mut c, mut k) = (counter, key);
    for round in 0..10 {
        if round > 0 {
            k = [k[0].wrapping_add(W0), k[1].wrapping_add(W1)];
        }
        let (hi0, lo0) = mul_hi_lo(M0, c[0]);
        let (hi1, lo1) = mul_hi_lo(M1, c[2]);
        c = [hi1 ^ c[1] ^ k[0], lo1, hi0 ^ c[3] ^ k[1], lo0];
    }
    c
}

/// A `u64` folded to 32 bits: its high word xor its low word.
#[inline]
fn fold(x: u64) -> u32 {
    (x as u32) ^ ((x >> 32) as u32)
}

/// A word as a uniform on the open interval (0, 1): `(x + ½) 2⁻³²`.
#[inline]
pub fn uniform_of_word(x: u32) -> f64 {
    (f64::from(x) + 0.5) * (1.0 / 4_294_967_296.0)
}

/// The Box–Muller normal deviate of the words `x2`, `x3` (each as [`uniform_of_word`]):
/// `√(−2 ln u₂) cos(2π u₃)`.
#[inline]
pub fn normal_of_words(x2: u32, x3: u32) -> f64 {
    let (u1, u2) = (uniform_of_word(x2), uniform_of_word(x3));
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

impl NoiseKey {
    /// Philox's counter and key for this key (module docs).
    pub fn counter_and_key(&self) -> ([u32; 4], [u32; 2]) {
        (
            [
                fold(self.cell),
                self.step as u32,
                (self.step >> 32) as u32,
                fold(self.stage),
            ],
            [self.seed as u32, (self.seed >> 32) as u32],
        )
    }

    /// The four words of the key.
    pub fn words(&self) -> [u32; 4] {
        let (counter, key) = self.counter_and_key();
        philox4x32_10(counter, key)
    }

    /// A uniform deviate on the open interval (0, 1), 53 random bits (the first two words).
    pub fn uniform(&self) -> f64 {
        let [x0, x1, ..] = self.words();
        let bits = (u64::from(x0) << 21) | u64::from(x1 >> 11);
        (bits as f64 + 0.5) * (1.0 / (1u64 << 53) as f64)
    }

    /// A standard normal deviate: Box–Muller on the last two words ([`normal_of_words`]).
    pub fn normal(&self) -> f64 {
        let [_, _, x2, x3] = self.words();
        normal_of_words(x2, x3)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Random123's known-answer vectors for Philox4x32-10 (its `tests/kat_vectors`): zeros,
    /// all ones, and the digits of π.
    #[test]
    fn philox_gives_random123s_known_answers() {
        let cases = [
            (
                [0u32; 4],
                [0u32; 2],
                [0x6627_e8d5, 0xe169_c58d, 0xbc57_ac4c, 0x9b00_dbd8],
            ),
            (
                [u32::MAX; 4],
                [u32::MAX; 2],
                [0x408f_276d, 0x41c8_3b0e, 0xa20b_c7c6, 0x6d54_51fd],
            ),
            (
                [0x243f_6a88, 0x85a3_08d3, 0x1319_8a2e, 0x0370_7344],
                [0xa409_3822, 0x299f_31d0],
                [0xd16c_fe09, 0x94fd_cceb, 0x5001_e420, 0x2412_6ea1],
            ),
        ];
        for (counter, key, expected) in cases {
            assert_eq!(
                philox4x32_10(counter, key),
                expected,
                "{counter:x?} {key:x?}"
            );
        }
    }

    /// Every stage the crate draws from folds to its own word, so no two kinds of draw share
    /// a counter.
    #[test]
    fn the_stages_in_use_fold_to_distinct_words() {
        let mut stages: Vec<u64> = Vec::new();
        for t in 0..4u64 {
            for k in 0..4u64 {
                stages.push((t << 16) + k);
                stages.push((1 << 62) + (t << 16) + k);
            }
        }
        stages.extend((0..4).map(|k| (1u64 << 61) + k));
        stages.push(1 << 60);
        let mut folded: Vec<u32> = stages.iter().map(|&s| fold(s)).collect();
        folded.sort_unstable();
        folded.dedup();
        assert_eq!(folded.len(), stages.len());
    }

    fn key(cell: u64, step: u64) -> NoiseKey {
        NoiseKey {
            seed: 7,
            cell,
            step,
            stage: 0,
        }
    }

    /// 200 000 deviates over cells and steps: mean 0 and variance 1 within 5 standard errors
    /// (σ/√n = 2.2e-3 for the mean, √2/√n = 3.2e-3 for the variance), the fourth moment
    /// within 5 standard errors of 3 (√96/√n = 0.022), and neighbouring keys uncorrelated
    /// (|r| < 5/√n = 0.011 for cells and for steps).
    #[test]
    fn the_deviates_are_standard_normal_and_independent() {
        let n = 200_000u64;
        let xs: Vec<f64> = (0..n).map(|k| key(k % 1000, k / 1000).normal()).collect();
        let nf = n as f64;
        let mean = xs.iter().sum::<f64>() / nf;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / nf;
        let m4 = xs.iter().map(|x| (x - mean).powi(4)).sum::<f64>() / nf;
        assert!(mean.abs() < 5.0 * 2.2e-3, "mean {mean}");
        assert!((var - 1.0).abs() < 5.0 * 3.2e-3, "variance {var}");
        assert!((m4 - 3.0).abs() < 5.0 * 0.022, "fourth moment {m4}");
        let corr =
            |f: &dyn Fn(u64) -> (f64, f64)| (0..n).map(f).map(|(a, b)| a * b).sum::<f64>() / nf;
        let next_cell = corr(&|k| (key(k, 3).normal(), key(k + 1, 3).normal()));
        let next_step = corr(&|k| (key(3, k).normal(), key(3, k + 1).normal()));
        let other_seed = corr(&|k| {
            let b = NoiseKey {
                seed: 8,
                ..key(k, 0)
            };
            (key(k, 0).normal(), b.normal())
        });
        for (what, r) in [
            ("cell", next_cell),
            ("step", next_step),
            ("seed", other_seed),
        ] {
            assert!(
                r.abs() < 5.0 / nf.sqrt(),
                "neighbouring {what}s correlate: {r}"
            );
        }
    }

    /// The same key gives the same deviate, whatever was drawn before.
    #[test]
    fn a_deviate_is_a_function_of_its_key() {
        let a = key(12, 99).normal();
        let _ = key(13, 99).normal();
        assert_eq!(a.to_bits(), key(12, 99).normal().to_bits());
        assert!(key(12, 99).uniform() > 0.0 && key(12, 99).uniform() < 1.0);
    }
}
