//! What a scene's validation says when it refuses ([`SceneError`], naming the key, the value,
//! what is wrong and the fix), the limits it checks against, and the helpers that write its
//! messages: a leaf, so that every check (`check/`, `division`, `walls`, `registry`) and the
//! validation that calls them need not import one another for it.

/// A problem with a scene, naming the key and the fix.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SceneError {
    /// The file could not be parsed (syntax, unknown key, wrong type).
    #[error("{0}")]
    Parse(String),
    /// A value is out of range.
    #[error("[{section}] {key} = {value}: {problem}; {fix}")]
    Invalid {
        /// The TOML table.
        section: &'static str,
        /// The key in it.
        key: &'static str,
        /// The offending value, as written.
        value: String,
        /// What is wrong.
        problem: String,
        /// What to do.
        fix: String,
    },
    /// A `[terms.NAME]` table of a term from a user's crate ([`crate::register_term`]): no
    /// such term is registered, or its builder refused a key.
    #[error("[terms.{name}]{}: {problem}; {fix}", if key.is_empty() { String::new() } else { format!(" {key}") })]
    Term {
        /// The term's name.
        name: String,
        /// The key of its table (empty for the table as a whole).
        key: String,
        /// What is wrong.
        problem: String,
        /// What to do.
        fix: String,
    },
    /// A saved state does not fit the scene (`init = "frame"`), or the scene was asked to
    /// build its tissue without the state it starts from.
    #[error("[cells] from = {from:?}: {problem}; {fix}")]
    State {
        /// The path of the saved state, as the scene gives it.
        from: String,
        /// What is wrong.
        problem: String,
        /// What to do.
        fix: String,
    },
}

/// The longest lattice side [`crate::SceneFile::validate`] accepts.
pub const MAX_SIDE: usize = 65536;

/// The most steps a run may take (relaxation and activity together): 10⁹, days of wall time
/// for the smallest scenes, and far below where the step counter or the clock lose precision.
pub const MAX_STEPS: f64 = 1e9;

/// The adaptive step's tolerance when `[integrator] tolerance` is not given.
pub const DEFAULT_TOLERANCE: f64 = 1e-3;

/// `v` with three significant digits, never rounded to 0.
pub(crate) fn sig3(v: f64) -> String {
    if v != 0.0 && !(0.01..1e4).contains(&v.abs()) {
        format!("{v:.2e}")
    } else {
        format!("{v:.3}")
    }
}

pub(crate) fn invalid(
    section: &'static str,
    key: &'static str,
    value: impl ToString,
    problem: impl Into<String>,
    fix: impl Into<String>,
) -> SceneError {
    SceneError::Invalid {
        section,
        key,
        value: readable(value.to_string()),
        problem: problem.into(),
        fix: fix.into(),
    }
}

/// A number as a person reads it: `1e-300`, not three hundred zeros.
pub(crate) fn readable(v: String) -> String {
    match v.parse::<f64>() {
        Ok(x) if x != 0.0 && x.is_finite() && (x.abs() < 1e-4 || x.abs() >= 1e12) => {
            format!("{x:e}")
        }
        _ => v,
    }
}
