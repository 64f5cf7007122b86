//! `aloft terrain LAT,LON... --terrain DIR`: the ground's height at places, from elevation
//! tiles read offline.
//!
//! Exit codes: 0 every place has a height; 1 a place has none (over no tile, or on a void: the
//! question is valid but the tiles hold no answer), said in one stderr line naming the place,
//! nothing on stdout; 2 bad input (a place that is not `LAT,LON` in range, no terrain directory,
//! a directory or tile that cannot be read), one stderr line naming it.

use std::io::Write;
use std::path::PathBuf;

use aloft::engine::error_line;
use aloft::terrain::{from_flag_or_env, heights, is_no_ground, Heights};
use anyhow::{Context, Result};
use clap::Args;

use super::{output, Format, Outcome};

#[derive(Debug, Args)]
pub struct TerrainArgs {
    /// Places as LAT,LON in degrees, north and east positive (44.2706,-71.3033). A place south
    /// of the equator starts with '-': give the places after `--`
    /// (`aloft terrain --terrain DIR -- -33.87,151.21`).
    #[arg(required = true, value_name = "LAT,LON", value_parser = point)]
    points: Vec<(f64, f64)>,
    /// The directory of elevation tiles: SRTM .hgt or .hgt.zip named by their south-west corner
    /// (N44W072.hgt), single-band GeoTIFF .tif in WGS 84 (default: the ALOFT_TERRAIN environment
    /// variable).
    #[arg(long, value_name = "DIR")]
    terrain: Option<PathBuf>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

/// A place typed as `LAT,LON`, degrees.
fn point(text: &str) -> Result<(f64, f64), String> {
    let (lat, lon) = text
        .split_once(',')
        .ok_or("not LAT,LON in degrees (such as 44.2706,-71.3033)")?;
    let number = |name: &str, s: &str, limit: f64| -> Result<f64, String> {
        let v: f64 = s
            .trim()
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| format!("{name} '{}' is not a number", s.trim()))?;
        match v.abs() <= limit {
            true => Ok(v),
            false => Err(format!("{name} {v} is outside -{limit} to {limit} deg")),
        }
    };
    Ok((
        number("latitude", lat, 90.0)?,
        number("longitude", lon, 180.0)?,
    ))
}

pub fn run(args: TerrainArgs) -> Result<Outcome> {
    let terrain = from_flag_or_env(args.terrain.as_deref())?
        .context("no terrain directory: give --terrain DIR or set ALOFT_TERRAIN")?;
    let answer = match heights(&terrain, &args.points) {
        Ok(a) => a,
        Err(e) if is_no_ground(&e) => {
            eprintln!("aloft terrain: {}", error_line(&e));
            return Ok(Outcome::Failed);
        }
        Err(e) => return Err(e.into()),
    };
    let mut out = std::io::stdout().lock();
    match args.format {
        Format::Json => output::write_json(&mut out, &answer)?,
        Format::Csv => write_csv(out, &answer)?,
        Format::Table => write_table(&mut out, &answer)?,
    }
    Ok(Outcome::Ok)
}

fn write_csv(out: impl Write, answer: &Heights) -> Result<()> {
    let records = answer.heights.iter().map(|h| {
        [
            h.latitude_deg.to_string(),
            h.longitude_deg.to_string(),
            h.height_m.to_string(),
        ]
    });
    output::write_csv(out, &["latitude_deg", "longitude_deg", "height_m"], records)
}

fn write_table(out: &mut impl Write, answer: &Heights) -> Result<()> {
    writeln!(
        out,
        "{:>12}  {:>12}  {:>9}",
        "latitude", "longitude", "height"
    )?;
    for h in &answer.heights {
        writeln!(
            out,
            "{:>12.6}  {:>12.6}  {:>7.1} m",
            h.latitude_deg, h.longitude_deg, h.height_m
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn places_are_lat_lon_in_range() {
        let (lat, lon) = point("44.2706,-71.3033").unwrap();
        assert!((lat - 44.2706).abs() < 1e-12 && (lon + 71.3033).abs() < 1e-12);
        assert!(point(" -33.9 , 151.2 ").is_ok());
        let say = |s: &str| point(s).unwrap_err();
        assert_eq!(say("44.27,x"), "longitude 'x' is not a number");
        assert_eq!(say("91,0"), "latitude 91 is outside -90 to 90 deg");
        assert_eq!(
            say("0,-180.5"),
            "longitude -180.5 is outside -180 to 180 deg"
        );
        assert_eq!(say("nan,0"), "latitude 'nan' is not a number");
        assert!(say("44.27").starts_with("not LAT,LON"));
    }
}
