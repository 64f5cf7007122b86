//! Identification from flight logs: a vehicle's model fitted to its logs (`aloft fit`, and the
//! vehicle made from a log's own figures), judged against them (`aloft validate`, with the
//! quality verdict), and a mission replayed on a flown log (`aloft mission --replay`).

pub(crate) mod fit;
pub(crate) mod fit_quality;
pub(crate) mod own_vehicle;
pub(crate) mod replay;
pub(crate) mod validate;
