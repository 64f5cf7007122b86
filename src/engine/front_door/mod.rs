//! The front door's own pieces: the option groups of the command line (`flags`, which the
//! Python keywords and the page's API share through `keywords`), the answers as the command
//! line's JSON text (`answers`) and the page's maps of a mission or a plan (`maps`). They stand
//! on top of every other folder and nothing below imports them.

pub mod answers;
pub mod flags;
pub(crate) mod keywords;
pub(crate) mod maps;
