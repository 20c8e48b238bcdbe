//! Physics terms from a user's crate, named in scene files.
//!
//! A program registers a term under a name with [`register_term`], giving the function that
//! builds it from its table; a scene then switches it on with a table `[terms.NAME]` (its keys
//! are the term's own, handed to that function), and `--set terms.NAME.KEY=VALUE` overrides
//! one. The term's state is written to frames and checkpoints like any term's (arrays
//! `NAME.VARIABLE`), so `rundir::RunDir::resume` in the same program continues such a run
//! bit for bit. `examples/custom-term` does all of it.
//!
//! ```
//! use std::sync::Arc;
//! use mechanics::terms::{CellContext, CellTerm};
//!
//! /// A constant push along x.
//! #[derive(Debug)]
//! struct Push(f64);
//! impl CellTerm for Push {
//!     fn name(&self) -> &str {
//!         "push"
//!     }
//!     fn force(&self, _cell: &CellContext<'_>, _x: &[f64]) -> [f64; 2] {
//!         [self.0, 0.0]
//!     }
//! }
//!
//! scene::register_term("push", |table| {
//!     let f = scene::TermError::number(table, "push", "f")?;
//!     Ok(Arc::new(Push(f)) as Arc<dyn CellTerm>)
//! });
//! let text = "[domain]\nlx = 48\nly = 48\n[cells]\ncount = 2\n[terms.push]\nf = 0.01\n";
//! let scene = scene::Scene::parse(text, &[]).unwrap();
//! assert_eq!(scene.terms().iter().map(|t| t.name().to_string()).collect::<Vec<_>>(), ["push"]);
//! let err = scene::Scene::parse(text, &["terms.push.f=\"x\"".into()]).unwrap_err();
//! assert!(err.to_string().starts_with("[terms.push] f"), "{err}");
//! ```

use std::collections::BTreeMap;
use std::sync::{Arc, OnceLock, RwLock};

use mechanics::terms::CellTerm;

use crate::SceneError;

/// What a term's builder says of a bad `[terms.NAME]` table, in the style of the scene's own
/// checks: the key, what is wrong with it and what to do.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TermError {
    /// The key of the table (empty for the table as a whole).
    pub key: String,
    /// What is wrong.
    pub problem: String,
    /// What to do.
    pub fix: String,
}

impl TermError {
    /// A bad key.
    pub fn new(key: impl Into<String>, problem: impl Into<String>, fix: impl Into<String>) -> Self {
        Self {
            key: key.into(),
            problem: problem.into(),
            fix: fix.into(),
        }
    }

    /// The finite number `key` of `table` (the term `term`'s), or an error that says so.
    ///
    /// # Errors
    /// A missing key, or one that is not a finite number.
    pub fn number(table: &toml::Table, term: &str, key: &str) -> Result<f64, TermError> {
        match table.get(key) {
            Some(toml::Value::Float(v)) if v.is_finite() => Ok(*v),
            Some(toml::Value::Integer(v)) => Ok(*v as f64),
            Some(other) => Err(TermError::new(
                key,
                format!("{other} is not a finite number"),
                format!("give {key} = a number in [terms.{term}]"),
            )),
            None => Err(TermError::new(
                key,
                "is required",
                format!("add {key} = a number to [terms.{term}]"),
            )),
        }
    }

    /// A table that serde could not read into the term's parameters (`table.clone().try_into()`
    /// in a builder), with the key serde names.
    pub fn from_serde(term: &str, e: &toml::de::Error) -> Self {
        let msg = e.to_string();
        let key = msg
            .lines()
            .find_map(|l| l.trim().strip_prefix("in `")?.strip_suffix('`'))
            .unwrap_or("")
            .to_string();
        TermError::new(
            key,
            msg.lines().next().unwrap_or("").to_string(),
            format!("see the term's documentation for the keys of [terms.{term}]"),
        )
    }
}

/// Builds a term from its table.
pub type TermBuilder =
    Arc<dyn Fn(&toml::Table) -> Result<Arc<dyn CellTerm>, TermError> + Send + Sync>;

fn registry() -> &'static RwLock<BTreeMap<String, TermBuilder>> {
    static REGISTRY: OnceLock<RwLock<BTreeMap<String, TermBuilder>>> = OnceLock::new();
    REGISTRY.get_or_init(Default::default)
}

/// Registers the term `name`, built by `build` from a scene's `[terms.NAME]` table, for every
/// scene this process parses from now on (runs, resumes, sweeps). Registering a name again
/// replaces its builder. The term the builder returns must be named `name`
/// ([`CellTerm::name`]): its state's arrays carry that name.
pub fn register_term(
    name: &str,
    build: impl Fn(&toml::Table) -> Result<Arc<dyn CellTerm>, TermError> + Send + Sync + 'static,
) {
    registry()
        .write()
        .unwrap_or_else(|e| e.into_inner())
        .insert(name.to_string(), Arc::new(build));
}

/// The names of the registered terms, in order.
pub fn registered_terms() -> Vec<String> {
    registry()
        .read()
        .unwrap_or_else(|e| e.into_inner())
        .keys()
        .cloned()
        .collect()
}

/// The term of the table `[terms.NAME]`, built by its registered builder.
///
/// # Errors
/// [`SceneError::Term`]: no term of that name is registered, the builder refused the table,
/// or it built a term of another name.
pub(crate) fn build(name: &str, table: &toml::Table) -> Result<Arc<dyn CellTerm>, SceneError> {
    let builder = registry()
        .read()
        .unwrap_or_else(|e| e.into_inner())
        .get(name)
        .cloned();
    let err = |key: &str, problem: String, fix: String| SceneError::Term {
        name: name.to_string(),
        key: key.to_string(),
        problem,
        fix,
    };
    let Some(builder) = builder else {
        let known = registered_terms();
        return Err(err(
            "",
            format!(
                "no term named {name:?} is registered in this program ({})",
                if known.is_empty() {
                    "it registers none".to_string()
                } else {
                    format!("it knows {}", known.join(", "))
                }
            ),
            "register it with scene::register_term before the scene is read (the monolayer binary knows only the built-in tables), or remove the table".into(),
        ));
    };
    let term = builder(table).map_err(|e| err(&e.key, e.problem, e.fix))?;
    if term.name() != name {
        return Err(err(
            "",
            format!("the registered builder made a term named {:?}", term.name()),
            format!("name the term {name:?} (its arrays in frames and checkpoints carry the name), or register it under its own"),
        ));
    }
    Ok(term)
}
