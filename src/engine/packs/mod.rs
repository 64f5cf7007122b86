//! Battery packs: a pack file flown with `--battery`, and a pack fitted from logs
//! (`aloft pack fit`: capacity, resistance, the open-circuit curve).

pub(crate) mod pack_file;
pub(crate) mod pack_fit;
