//! The modules of each library crate import one another without a cycle (issue 48), read from
//! the source: every `crate::NAME` path in a module's files (tests and comments left out) is
//! an edge to the top-level module `NAME`, or, for a name the crate root re-exports
//! (`pub use module::{A, B}` in lib.rs), to the module it comes from. A cycle means two parts
//! that cannot be understood, tested or changed one without the other (the knot of ten modules
//! in `mechanics` before issue 48: the kernels, the workspace, the terms, the tissue, its
//! extensions and the division clock all reached each other).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

type Graph = BTreeMap<String, BTreeSet<String>>;

/// The crates whose modules still form a cycle, each with the modules on it: the test fails
/// when another crate has one, and when one of these no longer has it (then remove it here).
/// None today (issue 48 untied mechanics', scene's and stability's).
const KNOWN_CYCLES: &[(&str, &[&str])] = &[];

/// What `lib.rs` re-exports at the crate root: the name, and the module it comes from.
fn root_exports(lib: &str) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    for stmt in lib.split("pub use ").skip(1) {
        let stmt = &stmt[..stmt.find(';').unwrap_or(stmt.len())];
        let Some((module, names)) = stmt.split_once("::") else {
            continue;
        };
        let names = names.trim().trim_start_matches('{').trim_end_matches('}');
        for name in names.split(',') {
            let name = name.trim().split("::").next().unwrap_or("").trim();
            if !name.is_empty() {
                out.insert(name.to_string(), module.trim().to_string());
            }
        }
    }
    out
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let path = e.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|x| x == "rs") {
            out.push(path);
        }
    }
}

/// The top-level modules of the crate whose sources are in `src`, and the modules each
/// names through `crate::`.
fn module_graph(src: &Path) -> Graph {
    let exports = root_exports(&std::fs::read_to_string(src.join("lib.rs")).unwrap());
    let mut files: Vec<(String, PathBuf)> = Vec::new();
    for e in std::fs::read_dir(src).unwrap() {
        let path = e.unwrap().path();
        let module = path.file_stem().unwrap().to_string_lossy().to_string();
        if path.is_dir() {
            let mut inside = Vec::new();
            rust_files(&path, &mut inside);
            files.extend(inside.into_iter().map(|f| (module.clone(), f)));
        } else if path.extension().is_some_and(|x| x == "rs") && module != "lib" {
            files.push((module, path));
        }
    }
    let modules: BTreeSet<String> = files.iter().map(|(m, _)| m.clone()).collect();
    let mut graph = Graph::new();
    for (module, path) in &files {
        let edges = graph.entry(module.clone()).or_default();
        // A module's tests (a `tests.rs` of its own, or after `#[cfg(test)]`) may reach
        // anything.
        if path.file_name().is_some_and(|f| f == "tests.rs") {
            continue;
        }
        let text = std::fs::read_to_string(path).unwrap();
        let code: String = text
            .split("#[cfg(test)]")
            .next()
            .unwrap()
            .lines()
            .filter(|l| !l.trim_start().starts_with("//"))
            .collect::<Vec<_>>()
            .join("\n");
        let mut add = |name: &str| {
            let top = name.trim().split("::").next().unwrap_or("").trim();
            let target = exports.get(top).map_or(top, String::as_str);
            if modules.contains(target) && target != module {
                edges.insert(target.to_string());
            }
        };
        for (k, _) in code.match_indices("crate::") {
            let rest = &code[k + "crate::".len()..];
            if let Some(inside) = rest.strip_prefix('{') {
                // `use crate::{a, b::c}`: each name in the braces.
                let inside = &inside[..inside.find('}').unwrap_or(inside.len())];
                inside.split(',').for_each(&mut add);
            } else {
                let name: String = rest
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                add(&name);
            }
        }
    }
    graph
}

/// A cycle of `graph` (its modules, the first repeated at the end), or `None`.
fn find_cycle(graph: &Graph) -> Option<Vec<String>> {
    fn visit(
        node: &str,
        graph: &Graph,
        path: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(k) = path.iter().position(|p| p == node) {
            let mut cycle = path[k..].to_vec();
            cycle.push(node.to_string());
            return Some(cycle);
        }
        if done.contains(node) {
            return None;
        }
        path.push(node.to_string());
        for next in graph.get(node).into_iter().flatten() {
            if let Some(c) = visit(next, graph, path, done) {
                return Some(c);
            }
        }
        path.pop();
        done.insert(node.to_string());
        None
    }
    let mut done = BTreeSet::new();
    graph
        .keys()
        .find_map(|node| visit(node, graph, &mut Vec::new(), &mut done))
}

/// The modules on some cycle of `graph`: those from which a path leads back to themselves.
fn on_cycles(graph: &Graph) -> BTreeSet<String> {
    let reach = |from: &str| -> BTreeSet<String> {
        let mut seen = BTreeSet::new();
        let mut stack: Vec<&str> = graph[from].iter().map(String::as_str).collect();
        while let Some(n) = stack.pop() {
            if seen.insert(n.to_string()) {
                stack.extend(graph.get(n).into_iter().flatten().map(String::as_str));
            }
        }
        seen
    };
    graph
        .keys()
        .filter(|m| reach(m).contains(*m))
        .cloned()
        .collect()
}

fn crates_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../crates")
}

#[test]
fn no_library_crate_has_a_cycle_among_its_modules() {
    let mut checked = 0;
    for e in std::fs::read_dir(crates_dir()).unwrap() {
        let src = e.unwrap().path().join("src");
        if !src.join("lib.rs").exists() {
            continue;
        }
        let name = src
            .parent()
            .unwrap()
            .file_name()
            .unwrap()
            .to_string_lossy()
            .to_string();
        let graph = module_graph(&src);
        let cycles = on_cycles(&graph);
        match KNOWN_CYCLES.iter().find(|(c, _)| *c == name) {
            Some((_, modules)) => {
                let want: BTreeSet<String> = modules.iter().map(|m| m.to_string()).collect();
                assert_eq!(
                    cycles, want,
                    "{name}: the modules on a cycle changed; update KNOWN_CYCLES (remove the crate when none are left)"
                );
            }
            None => assert_eq!(
                find_cycle(&graph),
                None,
                "{name}: a cycle among its modules (its graph: {graph:#?})"
            ),
        }
        checked += 1;
    }
    assert!(checked >= 10, "only {checked} library crates found");
}

/// The reader sees the imports this test is about (so that it cannot pass by reading
/// nothing): in `mechanics` the kernels read the evaluation's types and the scratch, the
/// division reads the clock; in `study` the analysis and the views read frames.
#[test]
fn the_reader_finds_the_imports() {
    let mechanics = module_graph(&crates_dir().join("mechanics/src"));
    for (from, to) in [
        ("kernels", "evaluation"),
        ("kernels", "scratch"),
        ("division", "clock"),
        ("extensions", "clock"),
        ("step", "tissue"),
    ] {
        assert!(
            mechanics[from].contains(to),
            "{from} → {to}: {mechanics:#?}"
        );
    }
    // `crate::Tissue`, re-exported at the root, counts as an import of `tissue`.
    assert!(mechanics["observables"].contains("tissue"));
    let study = module_graph(&crates_dir().join("study/src"));
    for user in ["analyze", "view"] {
        assert!(study[user].contains("frame"), "{user}: {:?}", study[user]);
        assert!(!study[user].contains(if user == "view" { "analyze" } else { "view" }));
    }
}

/// The cycle finder finds a cycle where there is one (analyze and view, which imported each
/// other before issue 48), and none in a chain.
#[test]
fn the_cycle_finder_finds_a_cycle_and_only_a_cycle() {
    let g = |edges: &[(&str, &str)]| {
        let mut g = Graph::new();
        for (a, b) in edges {
            g.entry(a.to_string()).or_default().insert(b.to_string());
            g.entry(b.to_string()).or_default();
        }
        g
    };
    let two = g(&[("analyze", "view"), ("view", "analyze"), ("view", "frame")]);
    assert_eq!(
        find_cycle(&two),
        Some(vec!["analyze".into(), "view".into(), "analyze".into()])
    );
    assert_eq!(
        on_cycles(&two),
        ["analyze", "view"].iter().map(|s| s.to_string()).collect()
    );
    let chain = g(&[("analyze", "frame"), ("view", "frame"), ("view", "region")]);
    assert_eq!(find_cycle(&chain), None);
    assert!(on_cycles(&chain).is_empty());
    let exports =
        root_exports("pub use tissue::Tissue;\npub use evaluation::{CellState, SumField};");
    assert_eq!(exports["Tissue"], "tissue");
    assert_eq!(exports["SumField"], "evaluation");
}
