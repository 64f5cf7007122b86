//! The air a flight flies in: the International Standard Atmosphere's troposphere, a day's
//! temperature, pressure and humidity, and the density they make.
//!
//! | symbol | meaning | value / unit |
//! |---|---|---|
//! | `T0`, `p0` | ISA sea-level temperature and pressure | 288.15 K, 101 325 Pa |
//! | `L` | ISA lapse rate, sea level to 11 km | 0.0065 K/m |
//! | `g0` | standard gravity | 9.80665 m/s^2 |
//! | `Rd` | gas constant of dry air (US Standard Atmosphere 1976) | 287.053 J/(kg K) |
//! | `Rv` | gas constant of water vapour | 461.495 J/(kg K) |
//! | `h` | elevation above mean sea level | m |
//! | `T` | air temperature | K |
//! | `p` | static (station) pressure | Pa |
//! | `e` | partial pressure of water vapour | Pa |
//!
//! - ISA temperature `T(h) = T0 - L h`; ISA pressure `p(h) = p0 (1 - L h / T0)^(g0 / (Rd L))`
//!   (the first layer of the US Standard Atmosphere 1976, as PX4's `atmosphere.cpp`).
//! - With a QNH (the pressure reduced to sea level by the ICAO atmosphere, as an altimeter
//!   setting), the station pressure is the same formula with QNH in place of `p0`.
//! - Density of moist air, the sum of the dry-air and vapour partial densities:
//!   `rho = (p - e) / (Rd T) + e / (Rv T)`, with `e = RH e_s(T)` and the saturation vapour
//!   pressure of Vaisala's fit `e_s = 611.6441 10^(7.591386 t / (t + 240.7263))` Pa (`t` in
//!   degrees Celsius; 0.083 % at most from the reference from -20 to +50 C).
//!
//! On a real day the temperature is the measured one and the pressure ISA's at the elevation (or
//! the QNH's): the density then differs from ISA's at the same elevation, by 1 % for 3 K.
//!
//! Check values (PX4 `src/lib/atmosphere/test_atmosphere.cpp`): `p(3000 m) = 70 109 Pa` (PX4's
//! test accepts 70 120 +- 10 with its gas constant 287.1), `rho(70 109 Pa, -4.5 C) = 0.9091`;
//! ISA sea level 1.2250 kg/m^3.

/// ISA sea-level temperature `T0`, K.
pub const ISA_SEA_LEVEL_TEMPERATURE_K: f64 = 288.15;
/// ISA sea-level pressure `p0`, Pa.
pub const ISA_SEA_LEVEL_PRESSURE_PA: f64 = 101_325.0;
/// ISA lapse rate `L` from sea level to 11 km, K/m.
pub const ISA_LAPSE_RATE_K_PER_M: f64 = 0.0065;
/// Gas constant of dry air `Rd`, J/(kg K) (US Standard Atmosphere 1976).
pub const DRY_AIR_GAS_CONSTANT_J_PER_KG_K: f64 = 287.053;
/// Gas constant of water vapour `Rv`, J/(kg K).
pub const WATER_VAPOUR_GAS_CONSTANT_J_PER_KG_K: f64 = 461.495;
/// Zero Celsius, K.
pub const ZERO_CELSIUS_K: f64 = 273.15;

/// The elevations the atmosphere answers for, m above mean sea level: from the shore of the Dead
/// Sea (-430 m, the lowest dry land) to the top of the ISA troposphere (11 km), where the lapse
/// rate ends.
pub const ELEVATION_RANGE_M: (f64, f64) = (-430.0, 11_000.0);
/// The air temperatures the atmosphere answers for, C: colder or hotter air than this is a
/// mistake (a unit slip: Kelvin or Fahrenheit), not a flight.
pub const TEMPERATURE_RANGE_C: (f64, f64) = (-60.0, 60.0);
/// The QNH values the atmosphere answers for, hPa: about the lowest and highest sea-level
/// pressures ever recorded (870 and 1084 hPa) with a margin.
pub const QNH_RANGE_HPA: (f64, f64) = (850.0, 1_100.0);

/// The largest share of the air's pressure its water vapour may have. Air at 100 % humidity
/// near its boiling point would be mostly steam: at 11,000 m, 60 C and QNH 850 hPa the
/// saturation vapour pressure (19.9 kPa) is above the air's own pressure (19.0 kPa). On
/// Earth's surface the vapour is at most about 4 % of the air (a 35 C day at 100 % humidity,
/// 5.6 kPa); a tenth leaves room for the hottest days that exist and refuses air that cannot.
pub const MAX_VAPOUR_FRACTION: f64 = 0.1;

/// The thinnest air the atmosphere answers for: ISA's density at the top of its troposphere
/// (11 km, -56.5 C), 0.3639 kg/m^3, kg/m^3. A day's combination that gives thinner air (a hot
/// day at 11 km) is outside the model's troposphere.
pub fn thinnest_density_kg_m3() -> f64 {
    isa_density_kg_m3(ELEVATION_RANGE_M.1)
}

/// The exponent `g0 / (Rd L)` of the ISA pressure law (5.2559).
fn pressure_exponent() -> f64 {
    crate::STANDARD_GRAVITY_MPS2 / (DRY_AIR_GAS_CONSTANT_J_PER_KG_K * ISA_LAPSE_RATE_K_PER_M)
}

/// ISA temperature at `elevation_m` above mean sea level, K.
pub fn isa_temperature_k(elevation_m: f64) -> f64 {
    ISA_SEA_LEVEL_TEMPERATURE_K - ISA_LAPSE_RATE_K_PER_M * elevation_m
}

/// Station pressure at `elevation_m` when the pressure reduced to sea level is `sea_level_pa`
/// (ISA's 101 325 Pa, or a day's QNH), by the ISA pressure law, Pa.
pub fn pressure_at_elevation_pa(elevation_m: f64, sea_level_pa: f64) -> f64 {
    sea_level_pa
        * (1.0 - ISA_LAPSE_RATE_K_PER_M * elevation_m / ISA_SEA_LEVEL_TEMPERATURE_K)
            .powf(pressure_exponent())
}

/// ISA pressure at `elevation_m`, Pa.
pub fn isa_pressure_pa(elevation_m: f64) -> f64 {
    pressure_at_elevation_pa(elevation_m, ISA_SEA_LEVEL_PRESSURE_PA)
}

/// Saturation vapour pressure over water at `temperature_c`, Pa (Vaisala's fit).
pub fn saturation_vapour_pressure_pa(temperature_c: f64) -> f64 {
    611.6441 * 10f64.powf(7.591386 * temperature_c / (temperature_c + 240.7263))
}

/// Density of air at `pressure_pa` and `temperature_k` with relative humidity
/// `relative_humidity` (a fraction, 0 dry to 1 saturated), kg/m^3.
pub fn air_density_kg_m3(pressure_pa: f64, temperature_k: f64, relative_humidity: f64) -> f64 {
    let e = relative_humidity * saturation_vapour_pressure_pa(temperature_k - ZERO_CELSIUS_K);
    (pressure_pa - e) / (DRY_AIR_GAS_CONSTANT_J_PER_KG_K * temperature_k)
        + e / (WATER_VAPOUR_GAS_CONSTANT_J_PER_KG_K * temperature_k)
}

/// ISA density at `elevation_m`, dry air, kg/m^3.
pub fn isa_density_kg_m3(elevation_m: f64) -> f64 {
    air_density_kg_m3(
        isa_pressure_pa(elevation_m),
        isa_temperature_k(elevation_m),
        0.0,
    )
}

/// The ISA elevation with the same density as `density_kg_m3` (the density altitude), m, found
/// by halving over 0.1 m from -5 km to 20 km (ISA's density falls monotonically there).
pub fn density_altitude_m(density_kg_m3: f64) -> f64 {
    let (mut lo, mut hi) = (-5_000.0, 20_000.0);
    while hi - lo > 0.1 {
        let mid = 0.5 * (lo + hi);
        if isa_density_kg_m3(mid) > density_kg_m3 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The figures of a day's air, each already within its range: the elevation, the temperature,
/// the humidity and the pressure reduced to sea level (ISA's 101 325 Pa, or the day's QNH).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Day {
    /// Elevation above mean sea level, m.
    pub elevation_m: f64,
    /// Air temperature, K.
    pub temperature_k: f64,
    /// Relative humidity, percent (0 dry to 100 saturated).
    pub humidity_percent: f64,
    /// Pressure reduced to sea level, Pa.
    pub sea_level_pa: f64,
}

/// The air a [`Day`] makes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DayAir {
    /// Static (station) pressure at the elevation, Pa.
    pub pressure_pa: f64,
    /// Density of the moist air, kg/m^3.
    pub density_kg_m3: f64,
}

/// Why a day whose figures are each in range combines into air that cannot exist.
/// (Not `non_exhaustive`: the two ways a day's air fails [`Day::air`]'s checks, matched whole by
/// callers that name the day in their own errors.)
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum ImpossibleAir {
    /// Water vapour at or above [`MAX_VAPOUR_FRACTION`] of the air's pressure.
    #[error("water vapour of {vapour_pa:.0} Pa in air of {pressure_pa:.0} Pa")]
    Vapour {
        /// The water vapour's partial pressure, Pa.
        vapour_pa: f64,
        /// The air's pressure, Pa.
        pressure_pa: f64,
    },
    /// A density below [`thinnest_density_kg_m3`] (ISA's at 11 km).
    #[error("a density of {density_kg_m3:.4} kg/m^3, below {min_density_kg_m3:.4} kg/m^3")]
    TooThin {
        /// The density of that air, kg/m^3.
        density_kg_m3: f64,
        /// The thinnest air the atmosphere answers for, kg/m^3.
        min_density_kg_m3: f64,
    },
}

impl Day {
    /// The station pressure at the elevation (ISA's pressure law from the sea-level pressure)
    /// and the density of the moist air there.
    ///
    /// # Errors
    /// [`ImpossibleAir::Vapour`] when the water vapour, `RH e_s(T)`, is at least
    /// [`MAX_VAPOUR_FRACTION`] of the pressure; [`ImpossibleAir::TooThin`] when the density is
    /// below [`thinnest_density_kg_m3`] (ISA's own 11 km is the limit itself, within a relative
    /// 1e-9 for its rounding).
    pub fn air(&self) -> Result<DayAir, ImpossibleAir> {
        let pressure_pa = pressure_at_elevation_pa(self.elevation_m, self.sea_level_pa);
        let density_kg_m3 = air_density_kg_m3(
            pressure_pa,
            self.temperature_k,
            self.humidity_percent / 100.0,
        );
        let vapour_pa = self.humidity_percent / 100.0
            * saturation_vapour_pressure_pa(self.temperature_k - ZERO_CELSIUS_K);
        if vapour_pa >= MAX_VAPOUR_FRACTION * pressure_pa {
            return Err(ImpossibleAir::Vapour {
                vapour_pa,
                pressure_pa,
            });
        }
        let min_density_kg_m3 = thinnest_density_kg_m3();
        if density_kg_m3 < min_density_kg_m3 * (1.0 - 1e-9) {
            return Err(ImpossibleAir::TooThin {
                density_kg_m3,
                min_density_kg_m3,
            });
        }
        Ok(DayAir {
            pressure_pa,
            density_kg_m3,
        })
    }
}

/// The density altitude of `density_kg_m3` ([`density_altitude_m`]) to the nearest 0.1 m (the
/// halving's resolution), never -0, m.
pub fn rounded_density_altitude_m(density_kg_m3: f64) -> f64 {
    (density_altitude_m(density_kg_m3) * 10.0).round() / 10.0 + 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn day(elevation_m: f64, temperature_c: f64, humidity_percent: f64, qnh_hpa: f64) -> Day {
        Day {
            elevation_m,
            temperature_k: ZERO_CELSIUS_K + temperature_c,
            humidity_percent,
            sea_level_pa: qnh_hpa * 100.0,
        }
    }

    /// Issue 41's impossible day (11,000 m, 60 C, 100 %, QNH 850 hPa): e_s(60 C) = 19.9 kPa
    /// against a station pressure of 19.0 kPa, vapour above a tenth of the air. The same day dry
    /// at QNH 1013.25 is 22.6 kPa at 333 K: 22 632 / (287.053 x 333.15) = 0.2367 kg/m^3, below
    /// ISA's 0.3639 at 11 km. ISA's own 11 km is air.
    #[test]
    fn a_day_that_cannot_exist_is_refused_by_what_is_wrong() {
        let steam = day(11_000.0, 60.0, 100.0, 850.0).air();
        assert!(
            matches!(steam, Err(ImpossibleAir::Vapour { vapour_pa, pressure_pa })
                if (vapour_pa - 19_900.0).abs() < 200.0 && (pressure_pa - 19_000.0).abs() < 200.0),
            "{steam:?}"
        );
        let thin = day(11_000.0, 60.0, 0.0, 1013.25).air();
        assert!(
            matches!(thin, Err(ImpossibleAir::TooThin { density_kg_m3, .. })
                if (density_kg_m3 - 0.2367).abs() < 5e-4),
            "{thin:?}"
        );
        let top = day(11_000.0, -56.5, 0.0, 1013.25).air().unwrap();
        assert!((top.density_kg_m3 - 0.36392).abs() < 2e-4);
        assert!(
            (top.pressure_pa - 22_632.0).abs() < 5.0,
            "{}",
            top.pressure_pa
        );
    }

    /// An ordinary day is its formulas: station pressure by the ISA law from the QNH, density
    /// of moist air at it (30 C, 80 %, sea level at ISA pressure: 1.1497 kg/m^3).
    #[test]
    fn an_ordinary_day_is_its_pressure_and_moist_density() {
        let air = day(0.0, 30.0, 80.0, 1013.25).air().unwrap();
        assert!((air.pressure_pa - 101_325.0).abs() < 1e-9);
        assert!((air.density_kg_m3 - 1.1497).abs() < 0.001);
    }

    /// The density altitude rounded to 0.1 m: ISA's density at 1234.5 m gives 1234.5 (the
    /// halving lands within 0.05 m), sea level gives 0 and never -0.
    #[test]
    fn the_rounded_density_altitude_is_to_a_tenth_of_a_metre() {
        let h = rounded_density_altitude_m(isa_density_kg_m3(1234.5));
        assert!((h - 1234.5).abs() < 0.1 + 1e-9, "{h}");
        assert!(((h * 10.0).round() - h * 10.0).abs() < 1e-6, "{h}");
        let zero = rounded_density_altitude_m(isa_density_kg_m3(0.0));
        assert!(zero.abs() < 0.1 && zero.to_bits() != (-0.0f64).to_bits());
    }

    /// PX4's test vectors (`test_atmosphere.cpp`): the pressure at 3000 m ISA, 70 109 Pa, within
    /// 20 Pa (the gas constants of the two codes differ: 287.053 against PX4's 287.1 moves it by
    /// 4 Pa, the research note's section 1.1); the density at that pressure and -4.5 C, 0.9091,
    /// within PX4's own tolerance 0.001; ISA sea level 1.225 to the fourth decimal.
    #[test]
    fn paper_val_px4_atmosphere_check_values() {
        assert!((isa_pressure_pa(0.0) - 101_325.0).abs() < 1e-9);
        assert!((isa_pressure_pa(3000.0) - 70_109.0).abs() < 20.0);
        assert!((isa_temperature_k(3000.0) - ZERO_CELSIUS_K - (-4.5)).abs() < 1e-9);
        assert!((air_density_kg_m3(70_109.0, ZERO_CELSIUS_K - 4.5, 0.0) - 0.9091).abs() < 0.001);
        assert!((isa_density_kg_m3(0.0) - crate::ISA_SEA_LEVEL_DENSITY_KG_M3).abs() < 5e-5);
        assert!((isa_density_kg_m3(1000.0) - 1.1116).abs() < 0.001);
        assert!((isa_density_kg_m3(3000.0) - 0.9091).abs() < 0.001);
    }

    /// A hot day at sea level: 101 325 Pa at 35 C is 1.1455 kg/m^3 (p / (Rd T) by hand:
    /// 101325 / (287.053 x 308.15) = 1.14549).
    #[test]
    fn a_hot_day_at_sea_level_is_thinner_by_the_ideal_gas_law() {
        let rho = air_density_kg_m3(101_325.0, ZERO_CELSIUS_K + 35.0, 0.0);
        assert!((rho - 101_325.0 / (287.053 * 308.15)).abs() < 1e-12);
        assert!((rho - 1.1455).abs() < 0.0005);
    }

    /// Moist air: e_s(30 C) = 42.43 hPa (the Smithsonian table, as quoted in the research
    /// note's section 1.3), and 30 C at 80 % humidity and 101 325 Pa is 1.1497 kg/m^3 against
    /// 1.1644 dry (-1.27 %): vapour is lighter than the dry air it displaces. Humidity 0 is the
    /// dry value exactly.
    #[test]
    fn moist_air_is_lighter_and_dry_air_is_the_dry_formula() {
        assert!((saturation_vapour_pressure_pa(30.0) - 4243.0).abs() < 10.0);
        let t = ZERO_CELSIUS_K + 30.0;
        let dry = air_density_kg_m3(101_325.0, t, 0.0);
        let moist = air_density_kg_m3(101_325.0, t, 0.8);
        assert!((moist - 1.1497).abs() < 0.001, "{moist}");
        assert!(((moist / dry - 1.0) * 100.0 - (-1.27)).abs() < 0.05);
        assert!((dry - 101_325.0 / (DRY_AIR_GAS_CONSTANT_J_PER_KG_K * t)).abs() < 1e-15);
    }

    /// A QNH of 1013.25 hPa is ISA's pressure law itself; a lower QNH lowers the station
    /// pressure in proportion.
    #[test]
    fn qnh_replaces_the_sea_level_pressure() {
        for h in [-400.0, 0.0, 1500.0, 4000.0] {
            assert!(
                (pressure_at_elevation_pa(h, ISA_SEA_LEVEL_PRESSURE_PA) - isa_pressure_pa(h)).abs()
                    < 1e-9
            );
            let low = pressure_at_elevation_pa(h, 99_000.0);
            assert!((low / isa_pressure_pa(h) - 99_000.0 / 101_325.0).abs() < 1e-12);
        }
    }

    /// ISA at 11 km is 0.3639 kg/m^3 (US Standard Atmosphere 1976, Table I: 3.6392e-1); the
    /// issue's impossible day (11,000 m, 60 C, QNH 850 hPa) has a saturation vapour pressure
    /// above its air's pressure.
    #[test]
    fn paper_val_the_thinnest_air_and_the_impossible_day() {
        assert!((thinnest_density_kg_m3() - 0.36392).abs() < 2e-4);
        let p = pressure_at_elevation_pa(11_000.0, 85_000.0);
        assert!(saturation_vapour_pressure_pa(60.0) > p, "{p}");
        assert!(
            saturation_vapour_pressure_pa(35.0) < MAX_VAPOUR_FRACTION * ISA_SEA_LEVEL_PRESSURE_PA
        );
    }

    /// The density altitude of ISA's own density at an elevation is that elevation (0.1 m).
    #[test]
    fn density_altitude_inverts_isa() {
        for h in [-300.0, 0.0, 1000.0, 2790.0, 8000.0] {
            assert!((density_altitude_m(isa_density_kg_m3(h)) - h).abs() < 0.1);
        }
        // The research note's table: 1000 m at 30 C is about 1740 m of density altitude.
        let rho = air_density_kg_m3(isa_pressure_pa(1000.0), ZERO_CELSIUS_K + 30.0, 0.0);
        assert!((density_altitude_m(rho) - 1740.0).abs() < 30.0);
    }
}
