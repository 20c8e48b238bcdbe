//! The pictures are real PNGs with the data where the axes say.

use render::{save_heatmaps, Heatmap, Plot, Series};

/// A plot of one horizontal series decodes as a PNG of the requested size, with the series'
/// colour (the first of the palette) on a horizontal row of pixels and the error bars
/// present, and a plot with nothing drawable is refused by name.
#[test]
fn a_plot_is_a_png_with_its_series_drawn() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("p.png");
    let mut plot = Plot::new("test", "x", "y");
    plot.series.push(Series::new("flat").with_points(
        &[0.0, 1.0, 2.0, 3.0],
        &[1.0, 1.0, 1.0, 1.0],
        &[0.1; 4],
    ));
    plot.series
        .push(Series::new("ramp").with_points(&[0.0, 3.0], &[0.0, 2.0], &[0.0, 0.0]));
    plot.save_png(&path).unwrap();
    let img = image::open(&path).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), plot.size);
    let blue = image::Rgb([31u8, 119, 180]);
    // The row with the most blue pixels is the flat series: it spans most of the plot width.
    let (best_row, count) = (0..img.height())
        .map(|y| {
            (
                y,
                (0..img.width())
                    .filter(|&x| *img.get_pixel(x, y) == blue)
                    .count(),
            )
        })
        .max_by_key(|r| r.1)
        .unwrap();
    assert!(count > 400, "flat line only {count} px wide");
    // y = 1 sits between y = 0 and y = 2, i.e. near the middle of the data range.
    let h = img.height() as f64;
    assert!(
        (best_row as f64) > 0.2 * h && (best_row as f64) < 0.7 * h,
        "{best_row}"
    );
    let empty = Plot::new("nothing", "x", "y");
    let e = empty
        .save_png(&dir.path().join("e.png"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("e.png") && e.contains("nothing"), "{e}");
}

/// A heatmap of +1 on the right half and −1 on the left is red on the right of the panel and
/// blue on the left; a panel of the wrong size is refused.
#[test]
fn a_heatmap_puts_the_colours_on_the_right_side() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("h.png");
    let side = 21;
    let values: Vec<f64> = (0..side * side)
        .map(|k| {
            if k / side > side / 2 {
                1.0
            } else if k / side < side / 2 {
                -1.0
            } else {
                0.0
            }
        })
        .collect();
    save_heatmaps(
        &path,
        "halves",
        &[Heatmap::new("u sign", side, values)],
        1,
        400,
    )
    .unwrap();
    let img = image::open(&path).unwrap().to_rgb8();
    let (red, blue) = (image::Rgb([178u8, 24, 43]), image::Rgb([33u8, 102, 172]));
    let mean_x = |c: image::Rgb<u8>| {
        let xs: Vec<u32> = img
            .enumerate_pixels()
            .filter(|p| *p.2 == c)
            .map(|p| p.0)
            .collect();
        assert!(xs.len() > 1000, "{} px", xs.len());
        xs.iter().map(|&x| x as f64).sum::<f64>() / xs.len() as f64
    };
    // The colour bar (right of the panel) holds a few pixels of each; the halves dominate.
    assert!(mean_x(red) > mean_x(blue) + 80.0);
    let bad = Heatmap::new("short", 5, vec![0.0; 7]);
    let e = save_heatmaps(&dir.path().join("b.png"), "", &[bad], 1, 200).unwrap_err();
    assert!(e.to_string().contains("short"), "{e}");
}
