//! A new part of the model reaches every consumer without a line of its own in them (issue
//! 48): a dummy term, `[terms.spin]`, with a per-cell angle that turns at a rate ω, the unit
//! vector of that angle as a derived per-cell vector, and an observable of its own, goes
//! through frames, checkpoints and a resume, `init = "frame"`, the ParaView cells file, the
//! render's arrows, the observables hook (a column of `observables.csv`) and a backend's
//! refusal by name, with nothing of it written anywhere but here.

use std::sync::Arc;

use mechanics::terms::{CellContext, CellTerm, NoiseKey};
use rundir::{Interrupt, RunDir};
use scene::Scene;
use study::view::{export_vtk, render_run, Frames, RenderOptions};

/// Each cell's angle turns at the rate `omega`; no force.
#[derive(Debug)]
struct Spin {
    omega: f64,
}

impl CellTerm for Spin {
    fn name(&self) -> &str {
        "spin"
    }

    fn state_names(&self) -> &[&'static str] {
        &["angle"]
    }

    fn derived(&self, x: &[f64]) -> Vec<(&'static str, &'static str, Vec<f64>)> {
        vec![(
            "spin",
            "the unit vector of the angle",
            vec![x[0].cos(), x[0].sin()],
        )]
    }

    fn observables(&self, x: &[f64], ids: &[usize]) -> Vec<(&'static str, f64)> {
        let n = ids.len() as f64;
        let (c, s) = ids
            .iter()
            .fold((0.0, 0.0), |(c, s), &i| (c + x[i].cos(), s + x[i].sin()));
        vec![("spin_order", (c / n).hypot(s / n))]
    }

    fn initial_state(&self, _id: usize, keys: &dyn Fn(u64) -> NoiseKey, out: &mut [f64]) {
        out[0] = std::f64::consts::TAU * keys(0).uniform();
    }

    fn rate(&self, _cell: &CellContext<'_>, _x: &[f64], out: &mut [f64]) {
        out[0] = self.omega;
    }
}

fn register() {
    scene::register_term("spin", |table| {
        let omega = scene::TermError::number(table, "spin", "omega")?;
        Ok(Arc::new(Spin { omega }) as Arc<dyn CellTerm>)
    });
}

const SCENE: &str = "[domain]\nlx = 48\nly = 48\n[cells]\ncount = 6\nradius = 6.0\n\
    [integrator]\nprecision = \"f64\"\nmargin = 10\n\
    [terms.spin]\nomega = 0.25\n\
    [run]\nrelax_time = 2\ntime = 6\noutput_every = 2\ncheckpoint_every = 2\nseed = 3\n";

fn run(dir: &std::path::Path, text: &str, set: &[&str]) {
    let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
    let scene = Scene::parse(text, &set).unwrap();
    let state = rundir::initial_state(&scene).unwrap();
    let run = RunDir::create(dir, scene, state, false, Interrupt::never()).unwrap();
    let (mut sim, _) = run.simulation::<f64>().unwrap();
    run.run(&mut sim).unwrap();
}

fn array(path: &std::path::Path, name: &str) -> Vec<f64> {
    rundir::read_npz(path, &[name]).unwrap().remove(0).data
}

#[test]
fn a_new_part_reaches_every_consumer() {
    register();
    let tmp = tempfile::tempdir().unwrap();
    let full = tmp.path().join("full");
    run(&full, SCENE, &[]);
    let frame = |dir: &std::path::Path, step: u64| dir.join(format!("frames/frame_{step:08}.npz"));
    let last = rundir::last_frame(&full).unwrap();

    // Frames: the state and the derived vector, by cell; the angle has turned by ω t.
    let (a0, a1) = (
        array(&frame(&full, 0), "spin.angle"),
        array(&frame(&full, last), "spin.angle"),
    );
    assert_eq!(a0.len(), 6);
    let t_last = array(&frame(&full, last), "time")[0];
    for (x0, x1) in a0.iter().zip(&a1) {
        assert!(
            (x1 - x0 - 0.25 * t_last).abs() < 1e-9,
            "{x0} → {x1} in {t_last}"
        );
    }
    let v = array(&frame(&full, last), "spin");
    assert_eq!(v.len(), 12);
    assert!((v[0] - a1[0].cos()).abs() < 1e-12 && (v[1] - a1[0].sin()).abs() < 1e-12);

    // Checkpoints and a resume: half a run resumed ends as the whole one, to the byte.
    let half = tmp.path().join("half");
    run(&half, SCENE, &["run.time=4"]);
    let resumed = RunDir::resume(&half, &["run.time=6".into()], Interrupt::never()).unwrap();
    let (mut sim, _) = resumed.simulation::<f64>().unwrap();
    resumed.run(&mut sim).unwrap();
    assert!(
        std::fs::read(frame(&full, last)).unwrap() == std::fs::read(frame(&half, last)).unwrap(),
        "the resumed run's last frame differs"
    );

    // init = "frame": a new run starts with the frame's angles.
    let from = format!("{SCENE}\n",).replace(
        "[cells]\ncount = 6\nradius = 6.0\n",
        &format!(
            "[cells]\ncount = 6\nradius = 6.0\ninit = \"frame\"\nfrom = \"{}\"\n",
            frame(&full, last).display()
        ),
    );
    let scene = Scene::parse(&from, &[]).unwrap();
    let t = rundir::initial_tissue::<f64>(&scene).unwrap();
    assert_eq!(t.terms().state("spin").unwrap(), &a1[..]);

    // The observables hook: the term's own, over the living cells.
    let ids: Vec<usize> = (0..t.n_cells()).collect();
    let obs = t.terms().observables(&ids);
    assert!(
        obs.len() == 1 && obs[0].0 == "spin_order" && (0.0..=1.0).contains(&obs[0].1),
        "{obs:?}"
    );

    // ...and the analysis writes it as a column of its own, after the documented ones.
    study::analyze::analyze(&full, &study::analyze::AnalyzeOptions::default()).unwrap();
    let table = std::fs::read_to_string(full.join("analysis/observables.csv")).unwrap();
    let mut lines = table.lines();
    assert_eq!(
        lines.next().unwrap(),
        format!("{},spin_order", rundir::OBSERVABLES_HEADER)
    );
    for line in lines {
        let v: f64 = line.rsplit(',').next().unwrap().parse().unwrap();
        assert!((0.0..=1.0).contains(&v), "{line}");
    }

    // ParaView: the cells file carries the state and the vector (3 components).
    let vtk = tmp.path().join("vtk");
    export_vtk(&full, &vtk, &Frames::Steps(vec![last]), &mut |_, _| {}).unwrap();
    let bytes = std::fs::read(vtk.join(format!("cells_{last:08}.vtp"))).unwrap();
    let text = String::from_utf8_lossy(&bytes);
    assert!(
        text.contains("Name=\"spin.angle\""),
        "no spin.angle in the .vtp"
    );
    let at = text
        .find("Name=\"spin\"")
        .expect("no spin vector in the .vtp");
    let tag = &text[text[..at].rfind('<').unwrap()..at + text[at..].find('>').unwrap()];
    assert!(tag.contains("NumberOfComponents=\"3\""), "{tag}");

    // The render's arrows are the part's vector: drawn with the option, not without.
    let draw = |arrows: bool| {
        let out = tmp.path().join(format!("png_{arrows}"));
        let opts = RenderOptions {
            polarity: arrows,
            frames: Frames::Steps(vec![last]),
            ..RenderOptions::default()
        };
        let info = render_run(&full, &out, &opts, &mut |_, _| {}).unwrap();
        std::fs::read(&info.files[0]).unwrap()
    };
    assert!(draw(true) != draw(false), "the arrows were not drawn");

    // A backend that has not implemented it refuses it by name (the GPU's own list is
    // tested in crates/cli/tests/gpu.rs).
    let params = scene.model_params(scene.zeta());
    let refused = mechanics::backend::unsupported_settings(
        &scene.configured_extensions().settings(&params),
        &[("[polarity] alpha", None)],
    );
    assert_eq!(refused.len(), 1);
    assert!(refused[0].starts_with("[terms.spin] = "), "{refused:?}");
}
