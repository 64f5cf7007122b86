//! The flights of one pack combined: the median of each per-flight estimate (a flight without
//! one, or with a value that is not finite, does not count), the charge drawn summed, the
//! equivalent cycles against the rated capacity. Arithmetic on [`PackReport`]s, no I/O.

use crate::PackReport;

/// The per-flight estimates of a pack combined over its flights.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FlightsCombined {
    /// Median of the flights' resistance from current steps, Ω.
    pub step_resistance_ohm: Option<f64>,
    /// Median of the autopilot's own resistance estimates, Ω.
    pub autopilot_resistance_ohm: Option<f64>,
    /// Median of the capacities estimated between rests, mA h.
    pub capacity_mah: Option<f64>,
    /// Charge drawn over all the flights, mA h.
    pub discharged_mah: f64,
    /// The rated capacity used for the cycles (the one given, else the flights' median), mA h.
    pub rated_capacity_mah: Option<f64>,
    /// Charge drawn / rated capacity.
    pub equivalent_cycles: Option<f64>,
}

/// The median of the finite values (`None` when there is none).
pub fn median_finite(values: impl IntoIterator<Item = f64>) -> Option<f64> {
    let mut v: Vec<f64> = values.into_iter().filter(|x| x.is_finite()).collect();
    crate::resistance::median(&mut v)
}

/// The flights combined; `rated_capacity_mah` given wins over the flights' own.
pub fn combine_flights(logs: &[PackReport], rated_capacity_mah: Option<f64>) -> FlightsCombined {
    let discharged_mah: f64 = logs.iter().filter_map(|r| r.discharged_mah).sum();
    let rated = rated_capacity_mah
        .or_else(|| median_finite(logs.iter().filter_map(|r| r.rated_capacity_mah)));
    FlightsCombined {
        step_resistance_ohm: median_finite(logs.iter().filter_map(|r| r.internal_resistance_ohm)),
        autopilot_resistance_ohm: median_finite(
            logs.iter()
                .filter_map(|r| r.autopilot_internal_resistance_ohm),
        ),
        capacity_mah: median_finite(logs.iter().filter_map(|r| r.capacity_mah)),
        discharged_mah,
        rated_capacity_mah: rated,
        equivalent_cycles: rated.map(|c| discharged_mah / c),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_even_and_not_finite() {
        assert_eq!(median_finite([3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median_finite([4.0, 1.0, 3.0, 2.0]), Some(2.5));
        assert_eq!(median_finite([f64::NAN, 5.0, f64::INFINITY]), Some(5.0));
        assert_eq!(median_finite([f64::NAN]), None);
        assert_eq!(median_finite([]), None);
    }

    fn report(
        r: Option<f64>,
        cap: Option<f64>,
        drawn: Option<f64>,
        rated: Option<f64>,
    ) -> PackReport {
        PackReport {
            internal_resistance_ohm: r,
            capacity_mah: cap,
            discharged_mah: drawn,
            rated_capacity_mah: rated,
            ..PackReport::default()
        }
    }

    #[test]
    fn flights_combined_by_median_and_sum() {
        let logs = [
            report(Some(0.030), Some(5000.0), Some(3000.0), Some(5200.0)),
            report(Some(0.020), None, Some(1000.0), Some(5200.0)),
            report(None, Some(4800.0), None, None),
        ];
        let c = combine_flights(&logs, None);
        assert_eq!(c.step_resistance_ohm, Some(0.025));
        assert_eq!(c.capacity_mah, Some(4900.0));
        assert!((c.discharged_mah - 4000.0).abs() < 1e-9);
        assert_eq!(c.rated_capacity_mah, Some(5200.0));
        assert_eq!(c.equivalent_cycles, Some(4000.0 / 5200.0));
        assert_eq!(c.autopilot_resistance_ohm, None);
        // The rated capacity given wins: 4000 mA h drawn of 8000 is half a cycle.
        assert_eq!(
            combine_flights(&logs, Some(8000.0)).equivalent_cycles,
            Some(0.5)
        );
    }
}
