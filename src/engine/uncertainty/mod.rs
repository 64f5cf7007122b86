//! How sure: the scenarios (wind speed and direction error, the model's power error, the pack's
//! capacity, the payload) flown for a mission or an endurance question, and their percentile
//! bands.

pub(crate) mod scenario_stats;
pub(crate) mod scenarios;
pub(crate) mod sortie_bands;
