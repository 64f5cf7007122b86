//! What every request stands on, below every other folder: the files a request reads and
//! writes (`files`, over `aloft_core::output`), flight logs read into samples (`logs`), numbers
//! checked finite before they leave (`finite`) and the work a caller bounds (`step_meter`).

pub(crate) mod files;
pub(crate) mod finite;
pub(crate) mod logs;
pub(crate) mod step_meter;
