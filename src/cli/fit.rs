//! `aloft fit`: identify the power model of a vehicle from flight logs.

use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::sync::Arc;

use anyhow::{bail, Context, Result};
use clap::Args;
use serde::Serialize;

use aloft::identify::force_samples;
use aloft::power::fit::{DragFit, FitParameter};
use aloft::power::{fit_drag, fit_power_model, FitOptions, PowerFit};
use aloft::propulsion::fit::battery::{fit_pack_resistance, PackResistanceFit};

use super::flights::{file_name, FlightLogs};
use super::output::{self, Row};
use super::{load_vehicle, Format, Outcome};

#[derive(Debug, Args)]
pub struct FitArgs {
    #[command(flatten)]
    logs: FlightLogs,
    /// Vehicle to start from (its [power] table): built-in name or TOML file.
    #[arg(long, value_name = "NAME|FILE")]
    vehicle_template: String,
    /// Where to write the fitted vehicle TOML.
    #[arg(short = 'o', long, value_name = "TOML")]
    output: PathBuf,
    /// Lumped constants to fit: k (= m g / eta), vh, profile, mu1, mu2, mu3 (comma-separated).
    /// Default: k. Drag (mu1..mu3) is fitted from the force balance when the logs carry
    /// acceleration, unless --aoa paper and mu* are listed here.
    #[arg(long, value_delimiter = ',', default_value = "k")]
    free: Vec<String>,
    /// Do not fit drag from the force balance (keep the template's mu1..mu3).
    #[arg(long)]
    no_drag: bool,
    /// Output format of the report (stdout).
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

fn parameter(name: &str) -> Result<FitParameter> {
    Ok(match name.trim().to_ascii_lowercase().as_str() {
        "k" | "eta" | "efficiency" => FitParameter::WeightOverEfficiency,
        "vh" => FitParameter::HoverInducedVelocity,
        "profile" | "kappa1" => FitParameter::Profile,
        "mu1" => FitParameter::Mu1,
        "mu2" => FitParameter::Mu2,
        "mu3" => FitParameter::Mu3,
        other => bail!("--free: unknown parameter '{other}' (k, vh, profile, mu1, mu2, mu3)"),
    })
}

#[derive(Serialize)]
pub struct LogReport {
    pub file: String,
    pub lag_s: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lag_correlation: Option<f64>,
    pub samples: usize,
    pub skipped: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pack: Option<PackResistanceFit>,
}

#[derive(Serialize)]
struct Report {
    logs: Vec<LogReport>,
    power: PowerFit,
    #[serde(skip_serializing_if = "Option::is_none")]
    drag: Option<DragFit>,
    output: String,
}

/// Pack resistance of one log, when it has voltage and current.
pub fn pack_fit(log: &aloft_logs::Log) -> Option<PackResistanceFit> {
    let (mut t, mut i, mut v) = (Vec::new(), Vec::new(), Vec::new());
    for s in &log.samples {
        if let (Some(cur), Some(vol)) = (s.current_a, s.voltage_v) {
            t.push(s.time_s);
            i.push(cur);
            v.push(vol);
        }
    }
    fit_pack_resistance(&t, &i, &v).ok()
}

pub fn run(args: FitArgs) -> Result<Outcome> {
    let template = load_vehicle(&args.vehicle_template)?;
    let mut vehicle = template.power_vehicle()?;
    let mut free = Vec::new();
    for name in &args.free {
        free.push(parameter(name)?);
    }
    let flights = args.logs.load()?;
    let mut logs = Vec::new();
    let mut samples = Vec::new();
    let mut forces = Vec::new();
    for (flight, log) in &flights {
        eprintln!(
            "aloft fit: {}: power lags motion by {:.2} s{}",
            file_name(&flight.source),
            flight.lag_s,
            flight
                .lag_correlation
                .map(|c| format!(" (correlation {c:.2})"))
                .unwrap_or_default()
        );
        samples.extend_from_slice(&flight.samples);
        forces.extend(force_samples(log));
        logs.push(LogReport {
            file: flight.source.clone(),
            lag_s: flight.lag_s,
            lag_correlation: flight.lag_correlation,
            samples: flight.samples.len(),
            skipped: flight.skipped,
            pack: pack_fit(log),
        });
    }

    // Drag from the force balance, unless asked of power.
    let drag_in_free = free
        .iter()
        .any(|p| matches!(p, FitParameter::Mu1 | FitParameter::Mu2 | FitParameter::Mu3));
    let drag = if args.no_drag || drag_in_free {
        None
    } else if forces.is_empty() {
        eprintln!(
            "aloft fit: the logs carry no acceleration: drag (mu1..mu3) kept from the template"
        );
        None
    } else {
        let d = fit_drag(vehicle.mass_kg(), vehicle.gravity_mps2(), &forces, 1.0, 5.0)
            .context("drag from the force balance")?;
        let mut p = vehicle.params().clone();
        [p.mu1_n_s_per_m, p.mu2_n_s2_per_m2, p.mu3_n_s3_per_m3] = d.mu_n;
        vehicle = aloft::power::Vehicle::new(p).context("fitted drag")?;
        Some(d)
    };

    let mut options = FitOptions::known_geometry();
    options.free = free;
    let bar = std::io::stderr().is_terminal().then(|| {
        let bar = indicatif::ProgressBar::new_spinner();
        bar.set_message("fitting");
        bar
    });
    if let Some(bar) = &bar {
        let b = bar.clone();
        options.progress = Some(Arc::new(move |i, cost| {
            b.set_message(format!(
                "Gauss-Newton iteration {i}, residual norm {cost:.1} W"
            ));
            b.tick();
        }));
    }
    let fit = fit_power_model(&vehicle, &samples, &options);
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    let fit = fit.context("power-model fit")?;

    // The fitted vehicle file: the template with its [power] table replaced.
    let mut fitted = template.clone();
    fitted.name = format!("{}-fitted", template.name);
    fitted.description = format!(
        "{} (fitted by aloft fit from {} log(s), RMSE {:.1} W, NRMSE {:.2} %)",
        template.description,
        args.logs.log.len(),
        fit.rmse_w,
        100.0 * fit.nrmse
    );
    fitted.power = Some(fit.vehicle.clone());
    let mut text = String::new();
    text.push_str(
        "# Written by `aloft fit`. Fitted constants (lumped; see aloft_power::fit::power):\n",
    );
    for p in &fit.parameters {
        text.push_str(&format!(
            "#   {} = {:.6e} +/- {:.2e} {}\n",
            p.name, p.value, p.std_error, p.unit
        ));
    }
    if let Some(d) = &drag {
        text.push_str(&format!(
            "# Drag from the force balance ({} samples, mass {} kg): mu = {:.4}, {:.5}, {:.6} (+/- {:.2e}, {:.2e}, {:.2e})\n",
            d.samples_used, vehicle.mass_kg(), d.mu_n[0], d.mu_n[1], d.mu_n[2], d.std_error[0], d.std_error[1], d.std_error[2]
        ));
    }
    for l in &logs {
        text.push_str(&format!(
            "# Log {}: lag {:.2} s, {} samples\n",
            l.file, l.lag_s, l.samples
        ));
    }
    text.push_str(&toml::to_string(&fitted).context("serialise the fitted vehicle")?);
    std::fs::write(&args.output, text)
        .with_context(|| format!("cannot write {}", args.output.display()))?;

    let report = Report {
        logs,
        power: fit,
        drag,
        output: args.output.display().to_string(),
    };
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    match args.format {
        Format::Json => output::write_json(&mut out, &report)?,
        Format::Csv => {
            let mut w = csv::Writer::from_writer(out);
            w.write_record(["name", "value", "std_error", "unit"])?;
            for p in &report.power.parameters {
                w.write_record([
                    p.name,
                    &p.value.to_string(),
                    &p.std_error.to_string(),
                    p.unit,
                ])?;
            }
            w.flush()?;
        }
        Format::Table => render(&mut out, &report)?,
    }
    Ok(Outcome::Ok)
}

fn render(out: &mut impl Write, r: &Report) -> Result<()> {
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
        "\nFitted vehicle -> {}: mass {} kg (template), efficiency {:.4}, rotor radius {:.4} m, kappa1 {:.4}, mu {:.4} {:.5} {:.6}",
        r.output, v.mass_kg, v.efficiency, v.rotor_radius_m, v.kappa1_w_per_n1_5, v.mu1_n_s_per_m, v.mu2_n_s2_per_m2, v.mu3_n_s3_per_m3
    )?;
    Ok(())
}
