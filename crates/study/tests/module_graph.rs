//! The modules of `study` import one another without a cycle (issue 48): the frame reader,
//! the tissue region and the error are leaves that the analysis and the views both use, and
//! neither of those imports the other. Read from the source: every `crate::NAME` path in a
//! module's files (its tests and comments left out) is an edge to the module `NAME`.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// The top-level modules of the crate at `src` and the modules each names through `crate::`.
fn module_graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mut files: Vec<(String, std::path::PathBuf)> = Vec::new();
    for e in std::fs::read_dir(src).unwrap() {
        let path = e.unwrap().path();
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        if path.is_dir() {
            let mut stack = vec![path.clone()];
            while let Some(d) = stack.pop() {
                for f in std::fs::read_dir(&d).unwrap() {
                    let f = f.unwrap().path();
                    if f.is_dir() {
                        stack.push(f);
                    } else if f.extension().is_some_and(|x| x == "rs") {
                        files.push((name.clone(), f));
                    }
                }
            }
        } else if path.extension().is_some_and(|x| x == "rs") && name != "lib" {
            files.push((name, path));
        }
    }
    let modules: BTreeSet<String> = files.iter().map(|(m, _)| m.clone()).collect();
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (module, path) in &files {
        let text = std::fs::read_to_string(path).unwrap();
        // Code only: a doc link such as [`crate::view`] is no import.
        let code: String = text
            .split("#[cfg(test)]")
            .next()
            .unwrap()
            .lines()
            .filter(|l| !l.trim_start().starts_with("//"))
            .collect::<Vec<_>>()
            .join("\n");
        let edges = graph.entry(module.clone()).or_default();
        for (k, _) in code.match_indices("crate::") {
            let rest = &code[k + "crate::".len()..];
            let name: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if modules.contains(&name) && &name != module {
                edges.insert(name);
            }
            // `use crate::{a, b::c}`: each name in the braces.
            if rest.starts_with('{') {
                let inside = &rest[1..rest.find('}').unwrap_or(rest.len())];
                for part in inside.split(',') {
                    let first = part.trim().split("::").next().unwrap_or("").trim();
                    if modules.contains(first) && first != module {
                        edges.insert(first.to_string());
                    }
                }
            }
        }
    }
    graph
}

/// The modules on a cycle of `graph`, as the cycle, or `None`.
fn find_cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        node: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
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
    for node in graph.keys() {
        if let Some(c) = visit(node, graph, &mut Vec::new(), &mut done) {
            return Some(c);
        }
    }
    None
}

#[test]
fn the_modules_of_study_import_each_other_without_a_cycle() {
    let graph = module_graph(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"));
    // The reader sees the imports this test is about (so that it cannot pass by reading
    // nothing): the analysis and the views read frames through `frame`.
    for user in ["analyze", "view"] {
        assert!(graph[user].contains("frame"), "{user}: {:?}", graph[user]);
    }
    assert_eq!(find_cycle(&graph), None, "the module graph: {graph:#?}");
}

/// The cycle finder finds a cycle where there is one (the two modules that imported each
/// other before issue 48), and none in a chain.
#[test]
fn the_cycle_finder_finds_a_cycle_and_only_a_cycle() {
    let g = |edges: &[(&str, &str)]| {
        let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for (a, b) in edges {
            g.entry(a.to_string()).or_default().insert(b.to_string());
            g.entry(b.to_string()).or_default();
        }
        g
    };
    assert_eq!(
        find_cycle(&g(&[("analyze", "view"), ("view", "analyze")])),
        Some(vec!["analyze".into(), "view".into(), "analyze".into()])
    );
    assert_eq!(
        find_cycle(&g(&[
            ("analyze", "frame"),
            ("view", "frame"),
            ("view", "region")
        ])),
        None
    );
}
