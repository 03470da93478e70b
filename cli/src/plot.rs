//! The plot `dalembert simulate` writes: coordinates against time, the
//! path of two coordinates with the collisions marked, and the energy drift.

use std::path::Path;

use dalembert::runtime::prelude::*;
use plotters::prelude::*;

use crate::sim::Row;

fn range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
        (l.min(x), h.max(x))
    });
    if !lo.is_finite() || !hi.is_finite() {
        return 0.0..1.0;
    }
    let pad = ((hi - lo) * 0.05).max(1e-12 * (1.0 + lo.abs().max(hi.abs())));
    lo - pad..hi + pad
}

/// Three panels: the coordinates over time, the path, and the energy drift.
pub fn plot<M: Surfaces<N>, const N: usize>(
    file: &Path,
    model: &M,
    rows: &[Row<'_, N>],
    axes: (usize, usize),
    e0: f64,
) -> Result<(), String> {
    let drawn = (|| -> Result<(), String> {
        let root = SVGBackend::new(file, (1000, 1200)).into_drawing_area();
        root.fill(&WHITE).map_err(text)?;
        let panels = root.split_evenly((3, 1));
        coordinates_panel(&panels[0], model, rows)?;
        path_panel(&panels[1], model, rows, axes)?;
        energy_panel(&panels[2], rows, e0)?;
        root.present().map_err(text)
    })();
    drawn.map_err(|e| format!("plotting {}: {e}", file.display()))
}

type Panel<'a> = DrawingArea<SVGBackend<'a>, plotters::coord::Shift>;

fn text(e: impl std::fmt::Display) -> String {
    e.to_string()
}

/// The time range of the rows.
fn times<const N: usize>(rows: &[Row<'_, N>]) -> std::ops::Range<f64> {
    0.0..rows.last().map_or(1.0, |r| r.t.max(1e-12))
}

/// Every coordinate against time.
fn coordinates_panel<M: Surfaces<N>, const N: usize>(
    area: &Panel<'_>,
    model: &M,
    rows: &[Row<'_, N>],
) -> Result<(), String> {
    let mut chart = ChartBuilder::on(area)
        .caption(format!("{}: coordinates", model.name()), ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(36)
        .y_label_area_size(60)
        .build_cartesian_2d(times(rows), range(rows.iter().flat_map(|r| r.q)))
        .map_err(text)?;
    chart.configure_mesh().x_desc("t").draw().map_err(text)?;
    for i in 0..N {
        let color = Palette99::pick(i).to_rgba();
        chart
            .draw_series(LineSeries::new(rows.iter().map(|r| (r.t, r.q[i])), color))
            .map_err(text)?
            .label(model.coordinate_names()[i])
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(text)
}

/// Coordinate b against coordinate a, the collisions marked.
fn path_panel<M: Surfaces<N>, const N: usize>(
    area: &Panel<'_>,
    model: &M,
    rows: &[Row<'_, N>],
    (a, b): (usize, usize),
) -> Result<(), String> {
    let names = model.coordinate_names();
    let mut path = ChartBuilder::on(area)
        .caption(
            format!("path: {} against {}", names[b], names[a]),
            ("sans-serif", 22),
        )
        .margin(12)
        .x_label_area_size(36)
        .y_label_area_size(60)
        .build_cartesian_2d(
            range(rows.iter().map(|r| r.q[a])),
            range(rows.iter().map(|r| r.q[b])),
        )
        .map_err(text)?;
    path.configure_mesh()
        .x_desc(names[a])
        .y_desc(names[b])
        .draw()
        .map_err(text)?;
    path.draw_series(LineSeries::new(rows.iter().map(|r| (r.q[a], r.q[b])), BLUE))
        .map_err(text)?;
    path.draw_series(
        rows.iter()
            .filter(|r| r.event.is_some())
            .map(|r| Circle::new((r.q[a], r.q[b]), 3, RED.filled())),
    )
    .map_err(text)?;
    Ok(())
}

/// E − E₀ against time.
fn energy_panel<const N: usize>(
    area: &Panel<'_>,
    rows: &[Row<'_, N>],
    e0: f64,
) -> Result<(), String> {
    let mut energy = ChartBuilder::on(area)
        .caption(
            format!("energy drift E − E₀ (E₀ = {e0:.6})"),
            ("sans-serif", 22),
        )
        .margin(12)
        .x_label_area_size(36)
        .y_label_area_size(80)
        .build_cartesian_2d(times(rows), range(rows.iter().map(|r| r.energy - e0)))
        .map_err(text)?;
    energy
        .configure_mesh()
        .x_desc("t")
        .y_label_formatter(&|y| format!("{y:.1e}"))
        .draw()
        .map_err(text)?;
    energy
        .draw_series(LineSeries::new(
            rows.iter().map(|r| (r.t, r.energy - e0)),
            RED,
        ))
        .map_err(text)?;
    Ok(())
}
