//! `aloft rotor`: rotor inertia, time constants and the simulated step response (transient seed).

use std::io::Write;

use anyhow::Result;
use clap::Args;

use aloft::engine::{rotor_response, EscProtocol, RotorAnswer, RotorOverrides, RotorRequest};

use aloft::engine::flags::finite;

use super::output::{self, Row};
use super::{Format, Outcome};

#[derive(Debug, Args)]
pub struct RotorArgs {
    /// A rotor TOML file or a built-in rotor (mn1806-6x2); flags below override its values.
    #[arg(long, value_name = "NAME|FILE")]
    rotor: Option<String>,
    /// Motor velocity constant Kv, rpm/V.
    #[arg(value_parser = finite(), long, allow_negative_numbers = true)]
    motor_kv: Option<f64>,
    /// Motor (armature + ESC) resistance, ohm.
    #[arg(value_parser = finite(), long, allow_negative_numbers = true)]
    motor_resistance: Option<f64>,
    /// No-load current, A.
    #[arg(value_parser = finite(), long, allow_negative_numbers = true)]
    no_load_current: Option<f64>,
    /// Supply voltage, V.
    #[arg(value_parser = finite(), long, allow_negative_numbers = true)]
    voltage: Option<f64>,
    /// Motor mass, g.
    #[arg(value_parser = finite(), long, allow_negative_numbers = true)]
    motor_mass: Option<f64>,
    /// Motor outer diameter, mm.
    #[arg(value_parser = finite(), long, allow_negative_numbers = true)]
    motor_diameter: Option<f64>,
    /// Propeller mass, g.
    #[arg(value_parser = finite(), long, allow_negative_numbers = true)]
    prop_mass: Option<f64>,
    /// Propeller diameter, inches.
    #[arg(value_parser = finite(), long, allow_negative_numbers = true)]
    prop_diameter: Option<f64>,
    /// Load-torque coefficient c of tau = c omega^2, N m s^2.
    #[arg(value_parser = finite(), long, allow_negative_numbers = true)]
    torque_coefficient: Option<f64>,
    /// ESC protocol whose latency (seed Table 4) is added: pwm, oneshot125, oneshot42, multishot, dshot150, dshot300, dshot600, ...
    #[arg(long)]
    protocol: Option<EscProtocol>,
    /// Step start speed, rad/s (default 0: from rest).
    #[arg(value_parser = finite(), long, allow_negative_numbers = true)]
    step_from: Option<f64>,
    /// Step end speed, rad/s (default: the steady speed at full voltage).
    #[arg(value_parser = finite(), long, allow_negative_numbers = true)]
    step_to: Option<f64>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

impl RotorArgs {
    fn request(&self) -> RotorRequest {
        RotorRequest {
            rotor: self.rotor.clone(),
            overrides: RotorOverrides {
                motor_kv_rpm_per_v: self.motor_kv,
                motor_resistance_ohm: self.motor_resistance,
                no_load_current_a: self.no_load_current,
                voltage_v: self.voltage,
                motor_mass_g: self.motor_mass,
                motor_diameter_mm: self.motor_diameter,
                prop_mass_g: self.prop_mass,
                prop_diameter_in: self.prop_diameter,
                torque_coefficient_nms2: self.torque_coefficient,
                protocol: self.protocol,
                step_from_radps: self.step_from,
                step_to_radps: self.step_to,
            },
        }
    }
}

pub fn run(args: RotorArgs) -> Result<Outcome> {
    let answer = rotor_response(&args.request())?;
    let mut out = std::io::stdout().lock();
    match args.format {
        Format::Json => output::write_json(&mut out, &answer)?,
        Format::Csv => output::write_csv_value(out, &answer.result)?,
        Format::Table => write_table(&mut out, &answer)?,
    }
    Ok(Outcome::Ok)
}

fn write_table(out: &mut impl Write, answer: &RotorAnswer) -> Result<()> {
    let r = &answer.result;
    let (kv, volts) = (answer.spec.motor_kv_rpm_per_v, answer.spec.voltage_v);
    let ms = |s: f64| format!("{:.1}", s * 1e3);
    let title = format!(
        "rotor step {:.0} -> {:.0} rad/s ({:.2} -> {:.2} V), Kv {} rpm/V, {} V supply",
        r.step_from_radps, r.step_to_radps, r.step_from_voltage_v, r.step_to_voltage_v, kv, volts
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
        Row::num("torque constant K_T = K_E", r.kt_nm_per_a, 5, "N m/A"),
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
        Row::num("settling band", r.settling_band_fraction * 100.0, 0, "%"),
        Row::num("steady current", r.steady_current_a, 2, "A"),
    ];
    output::write_table(out, &title, &rows)?;
    Ok(())
}
