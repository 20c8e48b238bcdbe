//! Tissue pictures on synthetic states: the pixels are where the geometry says.

use analysis::defects::detect;
use phasefield::Lattice;
use render::{Fill, LatticeVectors, Movie, Patches, Picture, TissuePicture, MINUS, PLUS};

const WHITE: [u8; 3] = [255, 255, 255];

/// One disc of radius `r` centred at `(cx, cy)` as a patch: φ = ½(1 − tanh((d − r)/2)),
/// which is ½ exactly at distance `r`.
fn disc(lattice: Lattice, cx: f64, cy: f64, r: f64, side: usize) -> Patches {
    let o = [
        lattice.wrap_x((cx - side as f64 / 2.0).round() as i64),
        lattice.wrap_y((cy - side as f64 / 2.0).round() as i64),
    ];
    let mut phi = vec![0.0; side * side];
    for u in 0..side {
        for v in 0..side {
            let (x, y) = ((o[0] + u) as f64, (o[1] + v) as f64);
            let d = lattice.distance([x, y], [cx, cy]);
            phi[u * side + v] = 0.5 * (1.0 - ((d - r) / 2.0).tanh());
        }
    }
    Patches {
        nx: side,
        ny: side,
        origins: vec![o],
        phi,
    }
}

/// The field pixels that are not background.
fn painted(pic: &Picture, p: &TissuePicture) -> Vec<(u32, u32)> {
    let (x0, y0) = p.to_pixel(0.0, p.ly as f64);
    let (x1, y1) = p.to_pixel(p.lx as f64, 0.0);
    let mut out = Vec::new();
    for y in y0 as u32..y1 as u32 {
        for x in x0 as u32..x1 as u32 {
            if pic.pixel(x, y) != WHITE {
                out.push((x, y));
            }
        }
    }
    out
}

/// A single disc of radius 12 draws as a filled disc of π (12 s)² pixels (s pixels per
/// node) centred where the lattice point maps, with its contour within 1.5 pixels of the
/// radius: the bilinear φ crosses ½ at most a fraction of a node from the true circle, since
/// the profile's curvature over one node is small.
#[test]
fn a_single_disc_is_a_filled_disc_of_the_right_radius() {
    let lattice = Lattice::new(64, 64);
    let r = 12.0;
    let mut p = TissuePicture::new(64, 64, 256);
    p.patches = disc(lattice, 30.0, 34.0, r, 40);
    let pic = p.draw().unwrap();
    let s = p.scale();
    let px = painted(&pic, &p);
    let want = std::f64::consts::PI * (r * s).powi(2);
    let got = px.len() as f64;
    assert!(
        (got - want).abs() < 0.02 * want,
        "{got} pixels, want {want}"
    );
    let (cx, cy) = p.to_pixel(30.0, 34.0);
    let (mx, my) = px.iter().fold((0.0, 0.0), |(a, b), &(x, y)| {
        (a + x as f64 + 0.5, b + y as f64 + 0.5)
    });
    assert!((mx / got - cx).abs() < 0.5 && (my / got - cy).abs() < 0.5);
    // The contour: dark pixels, all at distance r s from the centre.
    let contour: Vec<_> = px
        .iter()
        .filter(|&&(x, y)| pic.pixel(x, y) == [40, 40, 40])
        .collect();
    // A 4-connected digital circle of radius ρ has about 4√2 ρ boundary pixels (0.9 · 2πρ).
    assert!(contour.len() as f64 > 0.8 * 2.0 * std::f64::consts::PI * r * s);
    for &&(x, y) in &contour {
        let d = (x as f64 + 0.5 - cx).hypot(y as f64 + 0.5 - cy);
        assert!(
            (d - r * s).abs() < 1.5,
            "contour pixel at {d}, radius {}",
            r * s
        );
    }
}

/// A disc centred on the lattice's corner comes back in all four corners of the picture
/// (periodic images), with the area of one disc.
#[test]
fn a_disc_across_the_corner_is_drawn_in_all_four_corners() {
    let lattice = Lattice::new(64, 48);
    let mut p = TissuePicture::new(64, 48, 192);
    p.patches = disc(lattice, 0.0, 0.0, 10.0, 32);
    p.fill = Fill::Id;
    let pic = p.draw().unwrap();
    let px = painted(&pic, &p);
    let want = std::f64::consts::PI * (10.0 * p.scale()).powi(2);
    assert!((px.len() as f64 - want).abs() < 0.03 * want);
    for (x, y) in [(1.0, 1.0), (63.0, 1.0), (1.0, 47.0), (63.0, 47.0)] {
        let (i, j) = p.to_pixel(x, y);
        assert_ne!(pic.pixel(i as u32, j as u32), WHITE, "corner ({x}, {y})");
    }
    let (i, j) = p.to_pixel(32.0, 24.0);
    assert_eq!(pic.pixel(i as u32, j as u32), WHITE);
}

/// A director texture with a +½ defect at (20.5, 24.5) and a −½ at (44.5, 24.5): the
/// analysis finds them and the picture marks each at its pixel in its colour; the +½ comet's
/// tail points along its orientation ψ, not the other way. (Here ψ = π: near the +½ core
/// θ = φ₁/2 − π/2, the standard comet turned by 2 · (−π/2).)
#[test]
fn a_known_half_integer_texture_puts_the_marks_at_the_right_pixels() {
    let (lx, ly) = (64, 48);
    let lattice = Lattice::new(lx, ly);
    let (p1, p2) = ((20.5, 24.5), (44.5, 24.5));
    let (mut qxx, mut qxy) = (vec![0.0; lx * ly], vec![0.0; lx * ly]);
    for x in 0..lx {
        for y in 0..ly {
            let (xf, yf) = (x as f64, y as f64);
            let th = 0.5 * ((yf - p1.1).atan2(xf - p1.0) - (yf - p2.1).atan2(xf - p2.0));
            qxx[x * ly + y] = (2.0 * th).cos();
            qxy[x * ly + y] = (2.0 * th).sin();
        }
    }
    let found = detect(lattice, &qxx, &qxy);
    let near = |p: (f64, f64)| {
        found
            .iter()
            .find(|d| (d.x - p.0).abs() < 1.0 && (d.y - p.1).abs() < 1.0)
            .copied()
    };
    let plus = near(p1).expect("the +1/2 defect");
    let minus = near(p2).expect("the -1/2 defect");
    assert_eq!((plus.charge, minus.charge), (0.5, -0.5));
    assert!(
        (plus.angle.abs() - std::f64::consts::PI).abs() < 0.1,
        "psi = {}",
        plus.angle
    );
    let mut p = TissuePicture::new(lx, ly, 320);
    p.director = Some(LatticeVectors {
        a: qxx,
        b: qxy,
        every: 4,
    });
    p.defects = vec![plus, minus];
    p.mark = 8.0;
    let pic = p.draw().unwrap();
    let at = |x: f64, y: f64| {
        let (i, j) = p.to_pixel(x, y);
        pic.pixel(i as u32, j as u32)
    };
    assert_eq!(at(p1.0, p1.1), PLUS);
    assert_eq!(at(p2.0, p2.1), MINUS);
    let (c, s) = (5.0 * plus.angle.cos(), 5.0 * plus.angle.sin());
    assert_eq!(at(p1.0 + c, p1.1 + s), PLUS, "the tail along psi");
    assert_ne!(at(p1.0 - c, p1.1 - s), PLUS, "no tail opposite");
    // No mark far from both.
    let marks = (0..pic.height)
        .flat_map(|y| (0..pic.width).map(move |x| (x, y)))
        .filter(|&(x, y)| pic.pixel(x, y) == PLUS || pic.pixel(x, y) == MINUS);
    for (x, y) in marks {
        let (a, b) = p.to_pixel(p1.0, p1.1);
        let (c, d) = p.to_pixel(p2.0, p2.1);
        let reach = 8.0 * p.scale();
        let r1 = (x as f64 - a).hypot(y as f64 - b);
        let r2 = (x as f64 - c).hypot(y as f64 - d);
        assert!(r1 < reach || r2 < reach, "a mark at ({x}, {y})");
    }
}

/// Two cells of radius 8, at x = 16 and x = 48, on a 64 × 32 picture of 256 pixels.
fn two_cells() -> TissuePicture {
    let lattice = Lattice::new(64, 32);
    let a = disc(lattice, 16.0, 16.0, 8.0, 24);
    let b = disc(lattice, 48.0, 16.0, 8.0, 24);
    let mut p = TissuePicture::new(64, 32, 256);
    p.patches = Patches {
        nx: 24,
        ny: 24,
        origins: vec![a.origins[0], b.origins[0]],
        phi: [a.phi, b.phi].concat(),
    };
    p
}

/// Values fill the cells on a colour bar: the low cell gets viridis' dark end, the high one
/// its yellow end; mismatched arrays are refused with what is wrong.
#[test]
fn values_fill_cells_at_the_ends_of_the_colour_bar() {
    let mut p = two_cells();
    p.fill = Fill::Values {
        values: vec![1.0, 3.0],
        label: "area".into(),
        signed: false,
    };
    let pic = p.draw().unwrap();
    let at = |x: f64, y: f64| {
        let (i, j) = p.to_pixel(x, y);
        pic.pixel(i as u32, j as u32)
    };
    assert_eq!(at(16.0, 16.0), [68, 1, 84]);
    assert_eq!(at(48.0, 16.0), [253, 231, 37]);
    assert!(pic.width > p.size + 50, "room for the colour bar");
    p.fill = Fill::Values {
        values: vec![1.0],
        label: "area".into(),
        signed: false,
    };
    let e = p.draw().unwrap_err().to_string();
    assert!(e.contains("1 fill values for 2 cells"), "{e}");
}

/// A movie holds as many frames as were pushed: GIF and APNG decoded by their own crates;
/// a short or foreign movie is refused, and an .mp4 without ffmpeg says so.
#[test]
fn movies_hold_every_frame() {
    let dir = tempfile::tempdir().unwrap();
    let frames: Vec<Picture> = (0..4)
        .map(|k| Picture::filled(30, 20, [60 * k as u8, 0, 0]))
        .collect();
    for name in ["m.gif", "m.apng"] {
        let path = dir.path().join(name);
        let mut m = Movie::create(&path, 30, 20, 4, 5.0).unwrap();
        for f in &frames {
            m.push(f).unwrap();
        }
        assert_eq!(m.finish().unwrap(), 4);
        assert!(!dir.path().join(format!("{name}.partial")).exists());
        let n = if name.ends_with("gif") {
            let mut opts = gif::DecodeOptions::new();
            opts.set_color_output(gif::ColorOutput::RGBA);
            let mut d = opts.read_info(std::fs::File::open(&path).unwrap()).unwrap();
            let mut n = 0;
            while let Some(f) = d.read_next_frame().unwrap() {
                assert_eq!((f.width, f.height), (30, 20));
                n += 1;
            }
            n
        } else {
            let d = png::Decoder::new(std::fs::File::open(&path).unwrap());
            let mut r = d.read_info().unwrap();
            let told = r.info().animation_control().unwrap().num_frames;
            let mut buf = vec![0; r.output_buffer_size()];
            let mut n = 0;
            while r.next_frame(&mut buf).is_ok() {
                n += 1;
            }
            assert_eq!(told, 4);
            n
        };
        assert_eq!(n, 4, "{name}");
    }
    let mut m = Movie::create(&dir.path().join("short.gif"), 30, 20, 4, 5.0).unwrap();
    m.push(&frames[0]).unwrap();
    assert!(m
        .push(&Picture::filled(31, 20, WHITE))
        .unwrap_err()
        .to_string()
        .contains("31×20"));
    assert!(m.finish().unwrap_err().to_string().contains("1 of the 4"));
    assert!(!dir.path().join("short.gif").exists());
    let e = Movie::create(&dir.path().join("m.avi"), 30, 20, 4, 5.0).unwrap_err();
    assert!(e.to_string().contains(".gif, .apng or .mp4"));
    let has_ffmpeg = std::process::Command::new("ffmpeg")
        .arg("-version")
        .output()
        .is_ok();
    if !has_ffmpeg {
        let e = Movie::create(&dir.path().join("m.mp4"), 30, 20, 4, 5.0).unwrap_err();
        assert!(e.to_string().contains("ffmpeg on the PATH"), "{e}");
    }
}

/// Categories fill the cells with distinct colours and name them in a legend: two cells of
/// categories 0 and 1 get the palette's first two colours, the legend's swatches show them in
/// order right of the field, and a category without a name is refused.
#[test]
fn categories_fill_cells_with_distinct_colours_and_a_legend() {
    let mut p = two_cells();
    p.fill = Fill::Categories {
        of_cell: vec![1, 0],
        names: vec!["soft".into(), "stiff".into()],
    };
    let pic = p.draw().unwrap();
    let at = |x: f64, y: f64| {
        let (i, j) = p.to_pixel(x, y);
        pic.pixel(i as u32, j as u32)
    };
    let (c0, c1) = (render::category_colour(0), render::category_colour(1));
    assert_ne!(c0, c1);
    assert_eq!(at(16.0, 16.0), c1);
    assert_eq!(at(48.0, 16.0), c0);
    assert!(pic.width > p.size + 50, "room for the legend");
    // The swatches: 12 px squares from 10 px right of the field, 18 px apart.
    let (x, y) = (p.size + 16, 56 + 16);
    let first = (0..pic.height).find(|&y| pic.pixel(x, y) == c0);
    let second = (0..pic.height).find(|&y| pic.pixel(x, y) == c1);
    assert!(
        matches!((first, second), (Some(f), Some(s)) if s == f + 18),
        "swatches at {first:?} and {second:?} (field top near {y})"
    );
    p.fill = Fill::Categories {
        of_cell: vec![2, 0],
        names: vec!["soft".into(), "stiff".into()],
    };
    assert!(p.draw().unwrap_err().to_string().contains("category 2"));
}
