//! The picture of a state in memory (`view::render_state`, which Python's
//! `Simulation.render` draws) is the picture `render_run` draws of the frame written of that
//! state, to the byte: with polarity, two populations and dividing cells, in every colour and
//! with every overlay that a state in memory can have.

use std::path::Path;

use mechanics::Workspace;
use study::view::{render_run, render_state, Colour, Frames, RenderOptions};

#[test]
fn a_state_in_memory_is_drawn_as_its_frame_is() {
    let text = "[domain]\nlx = 60\nly = 60\n[cells]\ncount = 10\nradius = 6.0\n\
        [model]\nzeta = 0.01\n[integrator]\nmargin = 10\n\
        [[population]]\nname = \"a\"\ncount = 6\n[[population]]\nname = \"b\"\ncount = 4\nzeta = -0.01\n\
        [polarity]\nalpha = 0.02\nrotational_diffusion = 1e-3\n\
        [division]\ncycle_time = 6\ncycle_spread = 2\ngrowth_time = 2\nextrusion = 0.1\n\
        [run]\ntime = 14\nrelax_time = 2\noutput_every = 2\n";
    let scene = scene::Scene::parse(text, &[]).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    rundir::prepare(&run, false).unwrap();
    rundir::write_scene(&run, &scene).unwrap();
    let mut t = scene.tissue::<f32>().unwrap();
    let mut ws = Workspace::new(t.cells());
    for _ in 0..28 {
        t.step(&mut ws, &scene.step_params()).unwrap();
        t.set_active(t.time() >= 2.0);
        t.proliferate(&mut ws);
    }
    t.observe(&mut ws);
    rundir::write_frame(&run, &t, &ws).unwrap();
    let clock = t.proliferation().expect("a clock");
    rundir::write_lineage(&run, clock).unwrap();
    assert!(
        clock.lineage().any(|r| r.parent.is_some()),
        "no cell divided: the lineage colours would not be tested"
    );
    for (colour, director, polarity, events) in [
        (Colour::Population, true, true, false),
        (Colour::Pressure, false, false, true),
        (Colour::Generation, true, false, true),
        (Colour::Lineage, false, true, false),
    ] {
        let opts = RenderOptions {
            colour,
            director,
            defects: director,
            polarity,
            events,
            frames: Frames::Steps(vec![t.iteration()]),
            ..RenderOptions::default()
        };
        let out = dir.path().join("png");
        let info = render_run(&run, &out, &opts, &mut |_, _| {}).unwrap();
        let from_file = std::fs::read(&info.files[0]).unwrap();
        let in_memory = render_state(&scene, &t, &ws, &opts).unwrap();
        assert!(
            from_file == in_memory,
            "{colour:?}: the picture in memory differs from the frame's"
        );
        std::fs::remove_dir_all(Path::new(&out)).unwrap();
    }
    // Tracks need earlier frames: refused by name.
    let opts = RenderOptions {
        tracks: true,
        ..RenderOptions::default()
    };
    let e = render_state(&scene, &t, &ws, &opts)
        .unwrap_err()
        .to_string();
    assert!(e.contains("--tracks"), "{e}");
}
