//! Performance at a point and over a range: power in one flight state or a batch of them (the
//! four-term model of the seeds), the propulsion chain's hover and rotor response, endurance and
//! range in wind, and the payload sweep.

pub(crate) mod endurance;
pub(crate) mod payload_sweep;
pub(crate) mod power;
pub(crate) mod power_batch;
pub(crate) mod propulsion;
