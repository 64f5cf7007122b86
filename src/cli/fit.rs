//! `aloft fit`: identify the power model of a vehicle from flight logs.

use std::io::{IsTerminal, Write};
use std::sync::Arc;

use anyhow::Result;
use clap::Args;

use aloft::engine::flags::FitFlags;
use aloft::engine::{fit_logs, FitAnswer, FitRequest};

use super::flights::{escaped, file_name, write_verdict};
use super::output::{self, Row};
use super::{Format, Outcome};

#[derive(Debug, Args)]
// The command line always writes the fitted vehicle: -o is required here (optional in Python).
#[command(mut_arg("output", |a| a.required(true)))]
pub struct FitArgs {
    /// The engine's fit options (logs, alignment, template, constants, output file).
    #[command(flatten)]
    flags: FitFlags,
    /// Output format of the report (stdout).
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

pub fn run(args: FitArgs) -> Result<Outcome> {
    let template = args.flags.template()?;
    let request = args.flags.request()?;
    let bar = std::io::stderr().is_terminal().then(|| {
        let bar = indicatif::ProgressBar::new_spinner();
        bar.set_message("fitting");
        bar
    });
    let request = FitRequest {
        progress: bar.clone().map(|b| {
            Arc::new(move |i: u64, cost: f64| {
                b.set_message(format!(
                    "Gauss-Newton iteration {i}, residual norm {cost:.1} W"
                ));
                b.tick();
            }) as aloft::engine::FitProgress
        }),
        ..request
    };
    let answer = fit_logs(&template, &request);
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    let answer = match answer {
        Ok(a) => a,
        // No log can be used: the answer of a failed check (exit 1), saying why.
        Err(aloft::Error::NoUsableLog { reasons }) => {
            let mut out = std::io::stdout().lock();
            match args.format {
                // No fit, no verdict: the reason alone (never `"quality": null`).
                Format::Json => writeln!(out, "{}", serde_json::json!({ "reason": reasons }))?,
                _ => writeln!(out, "NO FIT: no log can be used: {}", escaped(&reasons))?,
            }
            return Ok(Outcome::Failed);
        }
        Err(e) => return Err(e.into()),
    };
    for s in &answer.skipped_logs {
        eprintln!(
            "aloft fit: skipped {}: {}",
            file_name(&s.file),
            escaped(&s.reason)
        );
    }
    for l in &answer.logs {
        eprintln!(
            "aloft fit: {}: power lags motion by {:.2} s{}",
            file_name(&l.file),
            l.lag_s,
            l.lag_correlation
                .map(|c| format!(" (correlation {c:.2})"))
                .unwrap_or_default()
        );
    }
    for n in &answer.notes {
        eprintln!("aloft fit: {n}");
    }
    let mut out = std::io::stdout().lock();
    match args.format {
        Format::Json => output::write_json(&mut out, &answer)?,
        Format::Csv => write_csv(out, &answer)?,
        Format::Table => render(&mut out, &answer)?,
    }
    Ok(Outcome::Ok)
}

/// The fitted constants: name, value, standard error and unit.
fn write_csv(out: impl Write, r: &FitAnswer) -> Result<()> {
    let records = r.power.parameters.iter().map(|p| {
        [
            p.name.to_string(),
            p.value.to_string(),
            p.std_error.to_string(),
            p.unit.to_string(),
        ]
    });
    output::write_csv(out, &["name", "value", "std_error", "unit"], records)
}

fn render(out: &mut impl Write, r: &FitAnswer) -> Result<()> {
    let n: usize = r.logs.iter().map(|l| l.samples).sum();
    writeln!(
        out,
        "aloft fit: {} log(s), {} aligned samples",
        r.logs.len(),
        n
    )?;
    writeln!(
        out,
        "  {:<44} {:>7} {:>6} {:>8} {:>12}",
        "log", "lag s", "corr", "samples", "pack R ohm"
    )?;
    for l in &r.logs {
        writeln!(
            out,
            "  {:<44} {:>7.2} {:>6} {:>8} {:>12}",
            file_name(&l.file),
            l.lag_s,
            l.lag_correlation
                .map(|c| format!("{c:.2}"))
                .unwrap_or_else(|| "given".into()),
            l.samples,
            l.pack
                .map(|p| format!("{:.4}+-{:.4}", p.resistance_ohm, p.resistance_std_error_ohm))
                .unwrap_or_else(|| "-".into())
        )?;
    }
    let p = &r.power;
    writeln!(
        out,
        "\nPower model: {} samples used, {} outliers dropped (beyond 5 robust sigma), {} Gauss-Newton iterations",
        p.samples_used, p.outliers_rejected, p.iterations
    )?;
    let rows: Vec<Row> = p
        .parameters
        .iter()
        .map(|q| {
            Row::new(
                q.name,
                format!("{:.6} +/- {:.2e}", q.value, q.std_error),
                q.unit,
            )
        })
        .collect();
    output::write_table(out, "  fitted constants", &rows)?;
    writeln!(
        out,
        "  residual RMSE {:.1} W, NRMSE {:.2} % of the mean measured power",
        p.rmse_w,
        100.0 * p.nrmse
    )?;
    if let Some(d) = &r.drag {
        writeln!(
            out,
            "\nDrag from the force balance ({} samples above 1 m/s, {} outliers): mu1 {:.4} +/- {:.2e}, mu2 {:.5} +/- {:.2e}, mu3 {:.6} +/- {:.2e}; residual {:.1} N",
            d.samples_used, d.outliers_rejected, d.mu_n[0], d.std_error[0], d.mu_n[1], d.std_error[1], d.mu_n[2], d.std_error[2], d.rmse_n
        )?;
    }
    let v = &p.vehicle;
    writeln!(
        out,
        "\nFitted vehicle -> {}: take-off mass {} kg without payload, efficiency {:.4}, rotor radius {:.4} m, kappa1 {:.4}, mu {:.4} {:.5} {:.6}",
        escaped(&r.output), v.mass_kg, v.efficiency, v.rotor_radius_m, v.kappa1_w_per_n1_5, v.mu1_n_s_per_m, v.mu2_n_s2_per_m2, v.mu3_n_s3_per_m3
    )?;
    Ok(write_verdict(
        out,
        r.quality,
        &r.quality_reasons,
        &r.skipped_logs,
    )?)
}
