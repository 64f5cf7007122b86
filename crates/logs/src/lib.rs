//! # aloft-logs
//!
//! Flight logs in, results out. Every source is converted on read to one model, [`Sample`]:
//! SI units, positions and velocities in east-north-up (ENU), attitude as aerospace Euler angles
//! relative to north-east-down (the convention of `aloft-power`), time in seconds from the first
//! sample. Gaps and non-monotonic time are reported in a [`TimeReport`], never smoothed over.
//!
//! Sources:
//! - CSV through a [`ColumnMap`]: built-in [`ColumnMap::kaist`], PX4 per-topic tables joined onto
//!   one time base ([`px4`]), or a user TOML map.
//! - MCAP ([`mcap_read`]): JSON and ROS 2 CDR messages of `sensor_msgs/BatteryState`,
//!   `geometry_msgs/PoseStamped`, `geometry_msgs/TwistStamped`, `nav_msgs/Odometry`,
//!   `sensor_msgs/Imu`, streamed with bounded memory.
//! - PX4 ULog ([`ulog`]) and ArduPilot DataFlash ([`dataflash`]), decoded here from bytes
//!   (sans-I/O: [`read_ulog`], [`read_dataflash`] take any reader, a `&[u8]` too), their topics
//!   joined onto the motion topic ([`join`]) with bounded memory; a corrupt or truncated log gives
//!   its valid prefix and warnings with byte offsets ([`BinarySummary`]).
//!
//! Output: [`mcap_write`] writes JSON-encoded MCAP with JSON Schemas that Foxglove displays, for
//! converted logs and for missions ([`write_mission_mcap`] takes plain slices).
//!
//! Analysis: [`InfoAccumulator`] (duration, rates, energy), [`estimate_lag_s`] (power vs motion),
//! [`GroundDetector`] (airborne spans and ground time, from the log's landed state or detected).
//!
//! ```no_run
//! use std::path::Path;
//! use aloft_logs::{read_log, McapOptions, Profile};
//! let log = read_log(Path::new("flight.csv"), Some(&Profile::Kaist), &McapOptions::default())?;
//! let (t, p) = log.power_series()?;
//! # Ok::<(), aloft_logs::LogError>(())
//! ```
//!
//! The library never prints or exits; every failure is a [`LogError`] naming the file and the
//! row, column, topic or channel.

#![deny(missing_docs)]
#![deny(clippy::float_cmp)]

pub mod battery_log;
pub mod battery_records;
pub mod binary;
mod binary_samples;
pub mod bytes;
pub mod cdr;
pub mod column_map;
pub mod csv_read;
pub mod dataflash;
pub mod error;
pub mod flight_events;
pub mod frame;
pub mod ground;
pub mod info;
pub mod join;
pub mod lag;
pub mod mcap_read;
pub mod mcap_records;
pub mod mcap_write;
pub mod modes;
pub mod open;
pub mod px4;
pub mod ros;
pub mod sample;
#[doc(hidden)]
pub mod synth;
pub mod telemetry;
pub mod ulog;

pub use battery_log::{read_battery_log, read_dataflash_battery, read_ulog_battery};
pub use battery_records::{BatteryLog, BatterySample};
pub use binary::{
    read_dataflash, read_ulog, BinaryLog, BinaryOptions, BinarySamples, BinarySummary,
};
pub use column_map::ColumnMap;
pub use csv_read::CsvSamples;
pub use error::{LogError, Result};
pub use ground::{GroundDetector, GroundOptions, GroundPoint, GroundReport, Span};
pub use info::{ChannelStats, InfoAccumulator, LogStats, PowerAccumulator, PowerStats};
pub use lag::{estimate_lag_s, resample_uniform, LagEstimate};
pub use mcap_read::{McapOptions, McapSamples, McapTime, TopicInfo};
pub use mcap_write::{
    write_log_mcap, write_mission_mcap, BatteryPoint, McapFile, McapWriter, MissionSample,
    PathPoint, PowerTerms, WriteSummary,
};
pub use open::{
    open_log, open_log_with, read_log, LogFormat, LogReader, OpenOptions, Profile, BUILTIN_PROFILES,
};
pub use px4::{Px4Options, Px4Samples};
pub use sample::{
    Attitude, Channel, DroppedValue, GeoOrigin, Log, Sample, TimeChecker, TimeReport,
};
