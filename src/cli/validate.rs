//! `aloft validate`: the power model against measured power, per flight and per airspeed band, in
//! the layout of the power seed's Table I, with the whole-flight energy error.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;

use aloft::engine::flags::ValidateFlags;
use aloft::engine::{validate_logs, PowerSeries, ValidateReport};

use super::flights::{escaped, file_name, quality_word, write_verdict};
use super::output::{self, ForceFlag};
use super::plot::ChartFile;
use super::{Format, Outcome};

#[derive(Debug, Args)]
pub struct ValidateArgs {
    /// The engine's validation options (logs, alignment, vehicle, pack, payload).
    #[command(flatten)]
    flags: ValidateFlags,
    /// Also write an SVG of measured against predicted power, one panel per flight.
    #[arg(long, value_name = "SVG")]
    plot: Option<PathBuf>,
    #[command(flatten)]
    force: ForceFlag,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

pub fn run(mut args: ValidateArgs) -> Result<Outcome> {
    args.force.check(args.plot.as_deref())?;
    let flying = aloft::engine::load_flying(&args.flags.vehicle, &mut args.flags.battery)?;
    let vehicle = flying.vehicle;
    let request = args.flags.request(args.plot.is_some());
    let answer = match validate_logs(&vehicle, &request) {
        Ok(a) => a,
        // No log can be used: a failed check (exit 1) that says why, as `aloft fit`.
        Err(aloft::Error::NoUsableLog { reasons }) => {
            let mut out = std::io::stdout().lock();
            match args.format {
                Format::Json => writeln!(out, "{}", serde_json::json!({ "reason": reasons }))?,
                _ => writeln!(
                    out,
                    "NO VALIDATION: no log can be used: {}",
                    escaped(&reasons)
                )?,
            }
            return Ok(Outcome::Failed);
        }
        Err(e) => return Err(e.into()),
    };
    for s in &answer.report.skipped_logs {
        eprintln!(
            "aloft validate: skipped {}: {}",
            file_name(&s.file),
            escaped(&s.reason)
        );
    }
    for f in &answer.report.flights {
        eprintln!(
            "aloft validate: {}: power lags motion by {:.2} s",
            file_name(&f.file),
            f.lag_s
        );
    }
    if let Some(path) = &args.plot {
        plot(args.force.chart(path), &answer.series)
            .with_context(|| format!("cannot write the plot {}", path.display()))?;
    }
    let report = &answer.report;
    let mut out = std::io::stdout().lock();
    match args.format {
        Format::Json => output::write_json(&mut out, report)?,
        Format::Csv => write_csv(out, report)?,
        Format::Table => render(&mut out, report)?,
    }
    Ok(Outcome::Ok)
}

fn write_csv(out: impl Write, report: &ValidateReport) -> Result<()> {
    let header = [
        "file",
        "duration_s",
        "lag_s",
        "measured_energy_wh",
        "predicted_energy_wh",
        "energy_error_percent",
        "nrmse_percent",
        "baseline_nrmse_percent",
        "calibrated_energy_error_percent",
        "calibrated_rmse_w",
        "best_constant_rmse_w",
        "quality",
    ];
    let opt = |x: Option<f64>| x.map(|v| v.to_string()).unwrap_or_default();
    let records = report.flights.iter().map(|f| {
        let c = f.calibration.as_ref();
        [
            f.file.clone(),
            f.duration_s.to_string(),
            f.lag_s.to_string(),
            f.measured_energy_wh.to_string(),
            f.predicted_energy_wh.to_string(),
            f.energy_error_percent.to_string(),
            f.nrmse_percent.to_string(),
            f.baseline_nrmse_percent.to_string(),
            opt(c.map(|c| c.energy_error_percent)),
            opt(c.map(|c| c.rmse_w)),
            opt(c.map(|c| c.best_constant_rmse_w)),
            quality_word(f.quality).to_string(),
        ]
    });
    output::write_csv(out, &header, records)
}

fn render(out: &mut impl Write, r: &ValidateReport) -> Result<()> {
    writeln!(
        out,
        "aloft validate: vehicle {}, {}, {} flight(s)",
        r.vehicle,
        r.mass,
        r.flights.len()
    )?;
    writeln!(
        out,
        "  {:<40} {:>6} {:>6} {:>9} {:>9} {:>7} {:>7} {:>8} {:>7}",
        "flight", "min", "lag s", "meas Wh", "pred Wh", "err %", "NRMSE%", "const %", "quality"
    )?;
    for f in &r.flights {
        writeln!(
            out,
            "  {:<40} {:>6.1} {:>6.2} {:>9.1} {:>9.1} {:>+7.2} {:>7.2} {:>8.2} {:>7}",
            file_name(&f.file),
            f.duration_s / 60.0,
            f.lag_s,
            f.measured_energy_wh,
            f.predicted_energy_wh,
            f.energy_error_percent,
            f.nrmse_percent,
            f.baseline_nrmse_percent,
            quality_word(f.quality)
        )?;
    }
    if r.flights.iter().any(|f| f.calibration.is_some()) {
        writeln!(
            out,
            "\nEfficiency re-estimated from the start of each flight; errors over the rest:"
        )?;
        writeln!(
            out,
            "  {:<40} {:>7} {:>7} {:>9} {:>9} {:>10}",
            "flight", "window", "eta", "err %", "RMSE W", "const W"
        )?;
        for f in &r.flights {
            if let Some(c) = &f.calibration {
                writeln!(
                    out,
                    "  {:<40} {:>6.0}s {:>7.4} {:>+9.2} {:>9.1} {:>10.1}",
                    file_name(&f.file),
                    c.calibrate_s,
                    c.efficiency,
                    c.energy_error_percent,
                    c.rmse_w,
                    c.best_constant_rmse_w
                )?;
            }
        }
    }
    writeln!(out, "\nMean NRMSE (%) with each term removed, by airspeed band in m/s (power seed Table I layout):")?;
    write!(out, "  {:<10} {:>7}", "dropped", "all")?;
    for b in r
        .table_i
        .first()
        .map(|row| row.bands.as_slice())
        .unwrap_or_default()
    {
        write!(out, " {:>7}", b.airspeed_band_mps)?;
    }
    writeln!(out)?;
    for row in &r.table_i {
        write!(out, "  {:<10} {:>7.2}", row.dropped_term, row.nrmse_percent)?;
        for b in &row.bands {
            match b.nrmse_percent {
                Some(x) => write!(out, " {:>7.2}", x)?,
                None => write!(out, " {:>7}", "-")?,
            }
        }
        writeln!(out)?;
    }
    Ok(write_verdict(
        out,
        r.quality,
        &r.quality_reasons,
        &r.skipped_logs,
    )?)
}

fn plot(file: ChartFile<'_>, series: &[PowerSeries]) -> Result<()> {
    let height = 260 * series.len().max(1) as u32;
    super::plot::svg_file(file, (1000, height), |root| {
        for (one, area) in series.iter().zip(root.split_evenly((series.len(), 1))) {
            plot_one(&area, one)?;
        }
        Ok(())
    })
}

/// One log's measured and predicted power against time.
fn plot_one(
    area: &plotters::drawing::DrawingArea<
        plotters::prelude::SVGBackend<'_>,
        plotters::coord::Shift,
    >,
    (name, t, measured, predicted): &PowerSeries,
) -> Result<()> {
    use plotters::prelude::*;
    if t.is_empty() {
        return Ok(());
    }
    let t0 = t[0];
    let t1 = t[t.len() - 1].max(t0 + 1.0);
    let hi = measured
        .iter()
        .chain(predicted)
        .copied()
        .fold(0.0, f64::max)
        * 1.05;
    let lo = measured
        .iter()
        .chain(predicted)
        .copied()
        .fold(f64::INFINITY, f64::min)
        * 0.95;
    let mut chart = ChartBuilder::on(area)
        .caption(
            format!(
                "{}: measured and predicted electrical power",
                file_name(name)
            ),
            ("sans-serif", 16),
        )
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(55)
        .build_cartesian_2d(0.0..(t1 - t0), lo..hi)?;
    chart
        .configure_mesh()
        .x_desc("time (s)")
        .y_desc("power (W)")
        .draw()?;
    for (values, color, label) in [(measured, BLUE, "measured"), (predicted, RED, "model")] {
        let line = t.iter().zip(values).map(|(x, y)| (x - t0, *y));
        super::plot::labelled_line(&mut chart, line, color, label, color)?;
    }
    super::plot::legend(&mut chart, SeriesLabelPosition::MiddleRight)
}
