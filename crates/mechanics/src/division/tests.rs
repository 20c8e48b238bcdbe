//! Tests of division (T5.1–T5.3 of the extensions).

use phasefield::{init, Lattice, PatchShape};
use rayon::prelude::*;

use super::*;
use crate::terms::{Polarity, Terms};
use crate::{ModelParams, StepParams};

/// One paper cell (R = 8) on `l × l`, margin 16, relaxed at rest for 100 TU.
fn relaxed_cell(l: usize) -> (Tissue, Workspace) {
    let lattice = Lattice::new(l, l);
    let shape = PatchShape::new(lattice, 16).unwrap();
    let c = l as f64 / 2.0;
    let cells = init::discs(lattice, shape, &[[c, c]], 8.0, 2.5);
    let mut t =
        Tissue::new(cells, ModelParams::paper(0.0)).with(Terms::new(3).with(Polarity::new(0.0)));
    let mut ws = Workspace::new(t.cells());
    for _ in 0..200 {
        t.step(&mut ws, &StepParams::default()).unwrap();
    }
    (t, ws)
}

/// T5.1: the split conserves φ node by node (to one rounding; the sum over the lattice of
/// `φ_a + φ_b − φ_m` is below 1e-12 of the cell's mass), the daughters get new identities, a
/// fresh polarity each and one slot each, and after 50 TU their centres lie on either side of
/// the mother's, more than R/2 from it along the division axis.
#[test]
fn a_division_conserves_the_field_and_the_daughters_separate() {
    let (mut t, mut ws) = relaxed_cell(64);
    let l = t.lattice();
    let mut mother = vec![0.0; l.len()];
    for x in 0..l.lx {
        for y in 0..l.ly {
            mother[l.index(x, y)] = t.cells().value_at(0, x, y);
        }
    }
    let c0 = t.centres()[0];
    let d = t.divide(0, [1.0, 0.0]);
    assert_eq!(d.mother, 0);
    assert_eq!(d.daughters, [1, 2]);
    assert_eq!(d.slots, [0, 1]);
    assert_eq!(t.cell_ids(), &[1, 2]);
    // φ_a + φ_b = φ_m at every node, to one rounding.
    let l = t.lattice();
    let (mut worst, mut sum, mut mass): (f64, f64, f64) = (0.0, 0.0, 0.0);
    for x in 0..l.lx {
        for y in 0..l.ly {
            let (fa, fb) = (t.cells().value_at(0, x, y), t.cells().value_at(1, x, y));
            let fm = mother[l.index(x, y)];
            worst = worst.max((fa + fb - fm).abs());
            sum += fa + fb - fm;
            mass += fm;
        }
    }
    assert!(worst <= 2.0 * f64::EPSILON, "{worst:e}");
    assert!(sum.abs() < 1e-12 * mass, "{sum:e} of {mass}");
    // A fresh polarity each: the daughters' angles are their own draws.
    let theta = t.terms().state("polarity").unwrap();
    assert_eq!(theta.len(), 3);
    assert!(theta[1] != theta[2] && theta[1] != theta[0]);
    ws.fit(t.cells());
    for _ in 0..100 {
        t.step(&mut ws, &StepParams::default()).unwrap();
    }
    let dx = |c: [f64; 2]| phasefield::min_image(c[0] - c0[0], l.lx as f64);
    let (xa, xb) = (dx(t.centres()[0]), dx(t.centres()[1]));
    eprintln!("daughters at {xa:.2} and {xb:.2} from the mother's centre after 50 TU");
    assert!(xa > 4.0 && xb < -4.0, "{xa} {xb}");
}

/// A small tissue of cells of radius 5 under a fast clock (`T₀ = 40`, `k = 0.05`), stepped
/// for `time` TU on the current thread pool: its lineage and its fields.
fn colony(time: f64, axis: SplitAxis) -> (Tissue, Proliferation) {
    let lattice = Lattice::new(96, 96);
    let shape = PatchShape::new(lattice, 10).unwrap();
    let cells = init::discs(lattice, shape, &[[30.0, 40.0], [66.0, 50.0]], 3.0, 2.5);
    let mut p = ModelParams::paper(0.0);
    p.energy.radius = 5.0;
    let mut t = Tissue::new(cells, p).with(Terms::new(5).with(Polarity::new(0.01)));
    let mut ws = Workspace::new(t.cells());
    let mut clock = Proliferation::new(40.0, 0.05, 9, &t)
        .with_axis(axis)
        .with_max_cells(40);
    let sp = StepParams::default();
    for _ in 0..(time / sp.dt) as usize {
        t.step(&mut ws, &sp).unwrap();
        clock.divide_due(&mut t, &mut ws);
    }
    (t, clock)
}

/// T5.3: every cell but the founders has a parent whose life ended by division at the
/// daughter's birth, and a generation one more than its parent's; the living cells are
/// exactly those whose life has not ended; and the colony is the same, to the bit, on one
/// thread and on two.
#[test]
fn the_lineage_is_whole_and_independent_of_threads() {
    let run = |threads: usize, axis| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| colony(160.0, axis))
    };
    for axis in [SplitAxis::Long, SplitAxis::Random] {
        let (t, clock) = run(2, axis);
        let records: Vec<&LineageRecord> = clock.lineage().collect();
        let n_div = records
            .iter()
            .filter(|r| matches!(r.death, Some((_, Ending::Division))))
            .count();
        eprintln!(
            "{axis:?}: {} cells now, {} in the lineage, {n_div} divisions, generations up to {}",
            t.n_cells(),
            records.len(),
            records.iter().map(|r| r.generation).max().unwrap()
        );
        assert!(n_div >= 4, "too few divisions to test: {n_div}");
        for r in &records {
            match r.parent {
                None => assert_eq!(r.generation, 0),
                Some(p) => {
                    let parent = records.iter().find(|q| q.id == p).expect("a parent");
                    assert_eq!(parent.death, Some((r.birth, Ending::Division)), "{r:?}");
                    assert_eq!(r.generation, parent.generation + 1);
                }
            }
        }
        let mut living: Vec<usize> = records
            .iter()
            .filter(|r| r.death.is_none())
            .map(|r| r.id)
            .collect();
        let mut ids = t.cell_ids().to_vec();
        living.sort_unstable();
        ids.sort_unstable();
        assert_eq!(living, ids);
        let (t1, _) = run(1, axis);
        assert_eq!(t1.cell_ids(), t.cell_ids());
        assert!(
            t1.cells().phi() == t.cells().phi(),
            "1 and 2 threads differ"
        );
    }
}

/// T5.2: one cell at low density (200² periodic, no activity) under `T₀ = 300`, `k = 0.01`
/// grows exponentially at the rate λ of the clock, `2 e^{−λ(T₀ + T_g)} k/(k + λ) = 1` (the
/// Euler–Lotka equation of a time between divisions `T₀ + Exp(1/k) + T_g`: without growth
/// λ = 1.78e-3, a doubling time of 389 TU against the mean cycle of 400), over three
/// generations and 20 seeds: the least-squares slope of `ln ⟨N⟩` from `T₀ + T_g` to
/// `1300 + 3 T_g` TU, within 15 %. Measured: −0.2 % without growth (⟨N⟩ = 6.75 at 1300 TU;
/// 5 s on 2 cores); with `T_g = 100`, −0.5 % (⟨N⟩ = 6.75 at 1600 TU), and the largest area
/// reached before a split 1.60 times a relaxed cell's (the area lags its target, which
/// reaches 2; asserted above 1.5, and below 1.2 without growth).
#[test]
fn a_colony_grows_at_the_rate_of_its_clock() {
    for t_g in [0.0, 100.0] {
        colony_growth(t_g);
    }
}

fn colony_growth(t_g: f64) {
    let (t0, k) = (300.0, 0.01);
    // λ by bisection.
    let f = |l: f64| 2.0 * (-l * (t0 + t_g)).exp() * k / (k + l) - 1.0;
    let (mut lo, mut hi) = (0.0, 0.01);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if f(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let lambda = 0.5 * (lo + hi);
    let dt = 0.5;
    let end = 1300.0 + 3.0 * t_g;
    let samples = (end / 50.0) as usize;
    let runs: Vec<(Vec<f64>, f64, f64)> = (0..20u64)
        .into_par_iter()
        .map(|seed| {
            let lattice = Lattice::new(200, 200);
            let shape = PatchShape::new(lattice, 16).unwrap();
            let cells = init::discs(lattice, shape, &[[100.0, 100.0]], 8.0, 2.5);
            let t = Tissue::new(cells, ModelParams::paper(0.0));
            let mut ws = Workspace::new(t.cells());
            // The founder starts its cycle at birth, as every later cell does.
            let mut clock = Proliferation::new(t0, k, seed, &t)
                .with_axis(SplitAxis::Random)
                .with_growth_time(t_g);
            clock.lineage[0].birth = 0.0;
            let mut t = t.with(clock);
            let (mut n, mut first_area, mut largest) = (Vec::new(), 0.0, 0.0f64);
            for step in 0..(end / dt) as usize {
                if step % 100 == 0 {
                    n.push(t.n_cells() as f64);
                }
                t.step(&mut ws, &StepParams::new(dt, 1)).unwrap();
                if step == 200 {
                    first_area = ws.cell(0).area;
                }
                largest = ws.cell_states().iter().fold(largest, |m, c| m.max(c.area));
                t.proliferate(&mut ws);
            }
            (n, first_area, largest)
        })
        .collect();
    let mean: Vec<f64> = (0..samples)
        .map(|s| runs.iter().map(|c| c.0[s]).sum::<f64>() / runs.len() as f64)
        .collect();
    let (x, y): (Vec<f64>, Vec<f64>) = (0..samples)
        .map(|s| (s as f64 * 50.0, mean[s].ln()))
        .filter(|&(time, _)| time >= t0 + t_g)
        .unzip();
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let slope = x
        .iter()
        .zip(&y)
        .map(|(a, b)| (a - mx) * (b - my))
        .sum::<f64>()
        / x.iter().map(|a| (a - mx) * (a - mx)).sum::<f64>();
    let relaxed = runs.iter().map(|r| r.1).sum::<f64>() / runs.len() as f64;
    let largest = runs.iter().map(|r| r.2).sum::<f64>() / runs.len() as f64;
    eprintln!(
        "T_g = {t_g}: growth rate {slope:.3e} /TU against the clock's {lambda:.3e} ({:+.1} %); <N> at {end} TU: {:.2}; largest area / relaxed area {:.2}",
        100.0 * (slope / lambda - 1.0),
        mean.last().unwrap(),
        largest / relaxed
    );
    assert!((slope / lambda - 1.0).abs() < 0.15);
    if t_g > 0.0 {
        assert!(largest / relaxed > 1.5, "{largest} against {relaxed}");
    } else {
        assert!(largest / relaxed < 1.2, "{largest} against {relaxed}");
    }
}

/// Three paper cells (R = 8) in a row on 96 × 64, margin 14, the middle one (cell 1) scaled
/// to a third of its field (an area of a ninth).
fn squeezed_trio() -> Tissue {
    let lattice = Lattice::new(96, 64);
    let shape = PatchShape::new(lattice, 14).unwrap();
    let cells = init::discs(
        lattice,
        shape,
        &[[20.0, 32.0], [48.0, 32.0], [76.0, 32.0]],
        8.0,
        2.5,
    );
    let mut t = Tissue::new(cells, ModelParams::paper(0.0));
    let plen = t.cells().patch_len();
    for v in &mut t.phi_mut()[plen..2 * plen] {
        *v /= 3.0;
    }
    t
}

/// The extrusion rule removes exactly the cells below the area fraction, records their end
/// in the lineage, and the tissue steps on with the others: three cells, one of them scaled
/// to a third of its field (an area of a ninth).
#[test]
fn cells_below_the_area_fraction_are_removed() {
    let mut t = squeezed_trio();
    let mut ws = Workspace::new(t.cells());
    let mut clock = Proliferation::new(1e9, 1.0, 1, &t);
    t.refresh(&mut ws);
    let removed = remove_extruded(&mut t, &mut ws, 0.2, Some(&mut clock));
    assert_eq!(removed, vec![1]);
    assert_eq!(t.cell_ids(), &[0, 2]);
    let r = clock.lineage().find(|r| r.id == 1).unwrap();
    assert_eq!(r.death, Some((0.0, Ending::Extrusion)));
    for _ in 0..10 {
        t.step(&mut ws, &StepParams::default()).unwrap();
    }
    assert!(remove_extruded(&mut t, &mut ws, 0.2, None).is_empty());
}

/// The paper's density relaxed to confluence: 30 cells on 71², 200 steps at ζ = 0, with its
/// evaluation in the workspace (the cells' pressures span 5.4e-3 to 1.3e-2).
fn relaxed_confluent() -> (Tissue<f64>, Workspace<f64>) {
    let lattice = Lattice::new(71, 71);
    let shape = PatchShape::new(lattice, 14).unwrap();
    let centres = init::positions(lattice, 30, 4.0, &init::Layout::Random { seed: 3 }).unwrap();
    let cells = init::discs(lattice, shape, &centres, 4.0, 2.5);
    let mut t0 = Tissue::new(cells, ModelParams::paper(0.0));
    let mut ws0 = Workspace::new(t0.cells());
    for _ in 0..200 {
        t0.step(&mut ws0, &StepParams::default()).unwrap();
    }
    t0.refresh(&mut ws0);
    (t0, ws0)
}

/// T5.4: contact inhibition of proliferation. A confluent tissue (the paper's density, 30
/// cells on 71²) under a fast clock (`T₀ = 40`, `k = 0.05`) divides less with the pressure
/// gate than without it, over 200 TU, the gate at the median cell pressure of the relaxed
/// tissue (9.3e-3; the cells' pressures span 5.4e-3 to 1.3e-2). Measured: 170 divisions
/// without the gate (the tissue reaches its cap of 200 cells), 3 with it, since every
/// division raises the pressure of the cells around. Asserted: fewer than three quarters.
#[test]
fn a_pressure_gate_slows_division_at_confluence() {
    let (t0, ws0) = relaxed_confluent();
    let mut p: Vec<f64> = (0..t0.n_cells())
        .map(|s| cell_pressure(&t0, &ws0, s))
        .collect();
    p.sort_by(f64::total_cmp);
    let median = p[p.len() / 2];
    let divisions = |gate: Option<f64>| {
        let (mut t, mut ws) = (t0.clone(), Workspace::new(t0.cells()));
        let mut clock = Proliferation::new(40.0, 0.05, 4, &t).with_max_cells(200);
        if let Some(g) = gate {
            clock = clock.with_pressure_gate(g);
        }
        let mut n = 0;
        for _ in 0..400 {
            t.step(&mut ws, &StepParams::default()).unwrap();
            n += clock.divide_due(&mut t, &mut ws).len();
        }
        n
    };
    let (free, gated) = (divisions(None), divisions(Some(median)));
    eprintln!(
        "pressures {:.2e} .. {:.2e}, median {median:.2e}; divisions in 200 TU: {free} without the gate, {gated} with it",
        p[0],
        p[p.len() - 1]
    );
    assert!(free >= 20, "{free}");
    assert!(
        (gated as f64) < 0.75 * free as f64,
        "{gated} against {free}"
    );
}

/// A simulation with the clock (observing every 10 steps) grows the same colony as the hand
/// loop of [`colony`], to the bit, cell for cell by identity. (Not re-sorting: the lattice
/// sums add cells in slot order, so a re-sorted run differs in the last bits, e.g. a centre by
/// 1e-14.)
#[test]
fn a_simulation_grows_the_colony_of_the_hand_loop() {
    let (hand, hand_clock) = colony(160.0, SplitAxis::Long);
    let lattice = Lattice::new(96, 96);
    let shape = PatchShape::new(lattice, 10).unwrap();
    let cells = init::discs(lattice, shape, &[[30.0, 40.0], [66.0, 50.0]], 3.0, 2.5);
    let mut p = ModelParams::paper(0.0);
    p.energy.radius = 5.0;
    let t = Tissue::new(cells, p).with(Terms::new(5).with(Polarity::new(0.01)));
    let clock = Proliferation::new(40.0, 0.05, 9, &t).with_max_cells(40);
    let counts = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let seen = counts.clone();
    let mut sim = crate::Simulation::new(t, StepParams::default())
        .with_proliferation(clock, None)
        .sort_every(None)
        .stop_time(160.0);
    sim.add_callback(
        "count",
        crate::Schedule::IterationInterval(10),
        move |o: &mut crate::Observation<f64>| {
            seen.lock().unwrap().push(o.tissue().n_cells());
            Ok(())
        },
    );
    sim.run().unwrap();
    let t = sim.tissue();
    let by_id = |t: &Tissue| {
        let mut v: Vec<(usize, [f64; 2])> = t
            .cell_ids()
            .iter()
            .zip(t.centres())
            .map(|(&i, &c)| (i, c))
            .collect();
        v.sort_by_key(|e| e.0);
        v
    };
    assert_eq!(by_id(t), by_id(&hand));
    let n_lineage = sim.proliferation().unwrap().lineage().count();
    assert_eq!(n_lineage, hand_clock.lineage().count());
    let counts = counts.lock().unwrap();
    assert!(counts.windows(2).all(|w| w[1] >= w[0]) && counts.last() > counts.first());
}

/// Three cells: cell 0 is due to divide, cell 1 is squeezed to a third of its field, cell 2
/// is neither. `Tissue::proliferate` with extrusion at 0.2 takes its decisions on the state
/// the step left, before any event: cell 0 divides and both daughters stay (a daughter in a
/// new slot has no area in the evaluation yet, which an extrusion decided after the division
/// would read as zero), cell 1 is extruded, and the lineage records both with where they
/// ended.
#[test]
fn proliferation_decides_before_it_acts() {
    let t = squeezed_trio();
    let record = |id: usize, cycle: f64| LineageRecord {
        id,
        parent: None,
        birth: -100.0,
        death: None,
        place: [f64::NAN; 2],
        generation: 0,
        cycle,
    };
    let clock = Proliferation::restore(
        1e9,
        1.0,
        5,
        [record(0, 50.0), record(1, 1e9), record(2, 1e9)],
    )
    .unwrap()
    .with_extrusion(0.2);
    assert!(Proliferation::restore(1.0, 1.0, 5, [record(0, 1.0), record(0, 2.0)]).is_err());
    let mut t = t.with(clock);
    let mut ws = Workspace::new(t.cells());
    t.refresh(&mut ws);
    let c1 = t.centres()[1];
    let events = t.proliferate(&mut ws);
    assert_eq!(events.divisions.len(), 1);
    assert_eq!(events.divisions[0].mother, 0);
    assert_eq!(events.removals, vec![(1, Ending::Extrusion)]);
    let mut ids = t.cell_ids().to_vec();
    ids.sort_unstable();
    assert_eq!(ids, vec![2, 3, 4]);
    let lineage: Vec<_> = t.proliferation().unwrap().lineage().copied().collect();
    assert_eq!(lineage[1].death, Some((0.0, Ending::Extrusion)));
    assert_eq!(lineage[1].place, c1);
    assert_eq!(lineage[0].death, Some((0.0, Ending::Division)));
    assert_eq!((lineage[3].parent, lineage[4].generation), (Some(0), 1));
    // The next step runs on the fitted workspace.
    t.step(&mut ws, &StepParams::default()).unwrap();
}

/// The death rate is a constant hazard: the lifespans drawn for 4000 identities at
/// `k_d = 0.01` have `P(L ≤ 1/k_d) = 1 − 1/e = 0.632` (measured within 4 standard errors,
/// 0.030) and mean `1/k_d` (within 4 standard errors, 6.3 %); a cell past its age is removed
/// as a death, with its place.
#[test]
fn deaths_follow_the_death_rate() {
    let lattice = Lattice::new(64, 64);
    let shape = PatchShape::new(lattice, 12).unwrap();
    let cells = init::discs(lattice, shape, &[[16.0, 32.0], [48.0, 32.0]], 6.0, 2.5);
    let t = Tissue::new(cells, ModelParams::paper(0.0));
    let clock = Proliferation::new(1e9, 1.0, 7, &t).with_death_rate(0.01);
    let n = 4000;
    let spans: Vec<f64> = (0..n).map(|id| clock.lifespan(id)).collect();
    let early = spans.iter().filter(|&&l| l <= 100.0).count() as f64 / n as f64;
    let mean = spans.iter().sum::<f64>() / n as f64;
    eprintln!("P(L <= 1/k) = {early:.4}, mean {mean:.1}");
    assert!((early - (1.0 - (-1.0f64).exp())).abs() < 0.030, "{early}");
    assert!((mean / 100.0 - 1.0).abs() < 0.063, "{mean}");
    // Cell by cell: a founder dies `phase·cycle + L` after its birth, i.e. `L` after the
    // start, whatever its age then.
    let mut t = t.with(clock.clone());
    let mut ws = Workspace::new(t.cells());
    let first = (0..2)
        .map(|id| clock.lifespan(id))
        .fold(f64::INFINITY, f64::min);
    let mut removed = Vec::new();
    while removed.is_empty() {
        t.step(&mut ws, &StepParams::default()).unwrap();
        removed = t.proliferate(&mut ws).removals;
    }
    assert_eq!(removed.len(), 1);
    assert_eq!(removed[0].1, Ending::Death);
    assert!(
        t.time() >= first && t.time() < first + 0.5 + 1e-9,
        "{} {first}",
        t.time()
    );
}

/// An identity is never given twice: after the cell with the largest identity is removed, the
/// next division's daughters get new identities above it (they once took the removed cell's,
/// so that its lineage record, term state and population were overwritten), and the terms'
/// state of the removed cell stays as it was.
#[test]
fn a_removed_cells_identity_is_not_given_again() {
    let (mut t, _ws) = relaxed_cell(64);
    let d = t.divide(0, [1.0, 0.0]);
    assert_eq!(d.daughters, [1, 2]);
    let theta_2 = t.terms().state("polarity").unwrap()[2];
    let slot_2 = t.cell_ids().iter().position(|&id| id == 2).unwrap();
    assert_eq!(t.remove(slot_2), 2);
    assert_eq!(t.next_id(), 3, "the removed identity 2 stays taken");
    let d = t.divide(0, [0.0, 1.0]);
    assert_eq!(d.mother, 1);
    assert_eq!(d.daughters, [3, 4]);
    assert_eq!(t.terms().state("polarity").unwrap()[2], theta_2);
    assert!(t.set_next_id(2).is_err(), "below a living identity");
}

/// The stress-based extrusion rule removes exactly the cells whose pressure `p_i` is above
/// its threshold, in the order of their identities, as extrusions; with the threshold above
/// every pressure it removes none. The relaxed confluent tissue of the pressure-gate test
/// (30 cells on 71², pressures from 5.4e-3 to 1.3e-2), the threshold at its upper quartile.
#[test]
fn the_pressure_rule_extrudes_the_compressed_cells() {
    let (t0, ws0) = relaxed_confluent();
    let by_id: Vec<(usize, f64)> = (0..t0.n_cells())
        .map(|s| (t0.cell_ids()[s], cell_pressure(&t0, &ws0, s)))
        .collect();
    let mut p: Vec<f64> = by_id.iter().map(|x| x.1).collect();
    p.sort_by(f64::total_cmp);
    let quartile = p[3 * p.len() / 4];
    let mut expected: Vec<usize> = by_id
        .iter()
        .filter(|x| x.1 > quartile)
        .map(|x| x.0)
        .collect();
    expected.sort_unstable();
    assert!(expected.len() >= 5, "{expected:?}");
    for (threshold, want) in [(quartile, expected), (p[p.len() - 1] * 1.01, Vec::new())] {
        let clock = Proliferation::new(1e9, 1.0, 4, &t0).with_extrusion_pressure(threshold);
        assert!(clock.extrudes());
        let mut t = t0.clone().with(clock);
        let mut ws = Workspace::new(t.cells());
        t.refresh(&mut ws);
        let events = t.proliferate(&mut ws);
        let removed: Vec<(usize, Ending)> =
            want.iter().map(|&id| (id, Ending::Extrusion)).collect();
        assert_eq!(events.removals, removed);
        assert!(events.divisions.is_empty());
        assert_eq!(t.n_cells(), 30 - want.len());
    }
}
