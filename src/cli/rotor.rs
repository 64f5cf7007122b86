//! `aloft rotor`: rotor inertia, time constants and the simulated step response (transient seed).

use std::path::Path;

use anyhow::{bail, Context, Result};
use clap::Args;

use aloft::propulsion::{rotor_step_response, EscProtocol, RotorSpec};

use super::output::{self, Row};
use super::{Format, Outcome};

/// Built-in rotors: name and TOML text.
const BUILTIN_ROTORS: &[(&str, &str)] = &[(
    "mn1806-6x2",
    include_str!("../../fixtures/rotors/mn1806-6x2.toml"),
)];

#[derive(Debug, Args)]
pub struct RotorArgs {
    /// A rotor TOML file or a built-in rotor (mn1806-6x2); flags below override its values.
    #[arg(long, value_name = "NAME|FILE")]
    rotor: Option<String>,
    /// Motor velocity constant Kv, rpm/V.
    #[arg(long, allow_negative_numbers = true)]
    motor_kv: Option<f64>,
    /// Motor (armature + ESC) resistance, ohm.
    #[arg(long, allow_negative_numbers = true)]
    motor_resistance: Option<f64>,
    /// No-load current, A.
    #[arg(long, allow_negative_numbers = true)]
    no_load_current: Option<f64>,
    /// Supply voltage, V.
    #[arg(long, allow_negative_numbers = true)]
    voltage: Option<f64>,
    /// Motor mass, g.
    #[arg(long, allow_negative_numbers = true)]
    motor_mass: Option<f64>,
    /// Motor outer diameter, mm.
    #[arg(long, allow_negative_numbers = true)]
    motor_diameter: Option<f64>,
    /// Propeller mass, g.
    #[arg(long, allow_negative_numbers = true)]
    prop_mass: Option<f64>,
    /// Propeller diameter, inches.
    #[arg(long, allow_negative_numbers = true)]
    prop_diameter: Option<f64>,
    /// Load-torque coefficient c of tau = c omega^2, N m s^2.
    #[arg(long, allow_negative_numbers = true)]
    torque_coefficient: Option<f64>,
    /// ESC protocol whose latency (seed Table 4) is added: pwm, oneshot125, oneshot42, multishot, dshot150, dshot300, dshot600, ...
    #[arg(long)]
    protocol: Option<EscProtocol>,
    /// Step start speed, rad/s (default 0: from rest).
    #[arg(long, allow_negative_numbers = true)]
    step_from: Option<f64>,
    /// Step end speed, rad/s (default: the steady speed at full voltage).
    #[arg(long, allow_negative_numbers = true)]
    step_to: Option<f64>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

fn base_spec(rotor: &str) -> Result<RotorSpec> {
    let (text, origin) = match BUILTIN_ROTORS.iter().find(|(n, _)| *n == rotor) {
        Some((_, t)) => (t.to_string(), format!("built-in rotor '{rotor}'")),
        None if Path::new(rotor).exists() => (
            std::fs::read_to_string(rotor).with_context(|| format!("cannot read {rotor}"))?,
            rotor.to_string(),
        ),
        None => bail!(
            "unknown rotor '{rotor}': not a built-in rotor ({}) and no such file",
            BUILTIN_ROTORS
                .iter()
                .map(|(n, _)| *n)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    toml::from_str(&text).with_context(|| format!("invalid rotor description {origin}"))
}

pub fn run(args: RotorArgs) -> Result<Outcome> {
    let mut spec = match &args.rotor {
        Some(r) => Some(base_spec(r)?),
        None => None,
    };
    let need = |v: Option<f64>, base: Option<f64>, flag: &str| -> Result<f64> {
        v.or(base).with_context(|| {
            format!(
                "missing {flag}: give it, or a rotor file with --rotor (e.g. --rotor mn1806-6x2)"
            )
        })
    };
    let b = spec.take();
    let spec = RotorSpec {
        motor_kv_rpm_per_v: need(
            args.motor_kv,
            b.as_ref().map(|s| s.motor_kv_rpm_per_v),
            "--motor-kv",
        )?,
        motor_resistance_ohm: need(
            args.motor_resistance,
            b.as_ref().map(|s| s.motor_resistance_ohm),
            "--motor-resistance",
        )?,
        no_load_current_a: need(
            args.no_load_current,
            b.as_ref().map(|s| s.no_load_current_a),
            "--no-load-current",
        )?,
        voltage_v: need(args.voltage, b.as_ref().map(|s| s.voltage_v), "--voltage")?,
        motor_mass_g: need(
            args.motor_mass,
            b.as_ref().map(|s| s.motor_mass_g),
            "--motor-mass",
        )?,
        motor_diameter_mm: need(
            args.motor_diameter,
            b.as_ref().map(|s| s.motor_diameter_mm),
            "--motor-diameter",
        )?,
        prop_mass_g: need(
            args.prop_mass,
            b.as_ref().map(|s| s.prop_mass_g),
            "--prop-mass",
        )?,
        prop_diameter_in: need(
            args.prop_diameter,
            b.as_ref().map(|s| s.prop_diameter_in),
            "--prop-diameter",
        )?,
        torque_coefficient_nms2: need(
            args.torque_coefficient,
            b.as_ref().map(|s| s.torque_coefficient_nms2),
            "--torque-coefficient",
        )?,
        protocol: args.protocol.or(b.as_ref().and_then(|s| s.protocol)),
        step_from_radps: args
            .step_from
            .or(b.as_ref().and_then(|s| s.step_from_radps)),
        step_to_radps: args.step_to.or(b.as_ref().and_then(|s| s.step_to_radps)),
    };
    let r = rotor_step_response(&spec).context("invalid rotor")?;
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    match args.format {
        Format::Json => output::write_json(&mut out, &r)?,
        Format::Csv => {
            let mut w = csv::Writer::from_writer(out);
            w.serialize(r)?;
            w.flush()?;
        }
        Format::Table => {
            let ms = |s: f64| format!("{:.1}", s * 1e3);
            let title = format!(
                "rotor step {:.0} -> {:.0} rad/s ({:.2} -> {:.2} V), Kv {} rpm/V, {} V supply",
                r.step_from_radps,
                r.step_to_radps,
                r.step_from_voltage_v,
                r.step_to_voltage_v,
                spec.motor_kv_rpm_per_v,
                spec.voltage_v
            );
            let rows = vec![
                Row::new(
                    "motor inertia (eq 9)",
                    format!("{:.3e}", r.motor_inertia_kgm2),
                    "kg m^2",
                ),
                Row::new(
                    "propeller inertia (eq 10)",
                    format!("{:.3e}", r.prop_inertia_kgm2),
                    "kg m^2",
                ),
                Row::new(
                    "torque constant K_T = K_E",
                    format!("{:.5}", r.kt_nm_per_a),
                    "N m/A",
                ),
                Row::new("time constant (eq 7)", ms(r.time_constant_s), "ms"),
                Row::new(
                    "linearised time constant",
                    ms(r.linearised_time_constant_s),
                    "ms",
                ),
                Row::new("rise time 10-90 % (simulated)", ms(r.rise_time_s), "ms"),
                Row::new("rise time 2.2 tau (eq 8)", ms(r.rise_time_eq8_s), "ms"),
                Row::new("ESC protocol delay (Table 4)", ms(r.protocol_delay_s), "ms"),
                Row::new(
                    "settling time (simulated + delay)",
                    ms(r.settling_time_s),
                    "ms",
                ),
                Row::new(
                    "settling band",
                    format!("{:.0}", r.settling_band_fraction * 100.0),
                    "%",
                ),
                Row::new("steady current", format!("{:.2}", r.steady_current_a), "A"),
            ];
            output::write_table(&mut out, &title, &rows)?;
        }
    }
    Ok(Outcome::Ok)
}
