//! Which format a mission text is in, from its content (a `.txt` may be a waypoints file, a
//! `.json` a plan).
//!
//! - `QGC WPL` on the first line: a `.waypoints` file ([`SourceFormat::QgcWpl`]; the reader
//!   checks the version, 110);
//! - a JSON object with a top-level `fileType` or `mission` key: a QGroundControl `.plan`
//!   ([`SourceFormat::QgcPlan`]; the reader checks that `fileType` is "Plan");
//! - any other JSON object: aloft's JSON mission ([`SourceFormat::AloftJson`]);
//! - anything else: aloft's TOML mission ([`SourceFormat::AloftToml`]), whose reader says what
//!   is wrong with it.
//!
//! A byte-order mark and leading blank space are passed over.

use serde::de::IgnoredAny;
use serde::Deserialize;

use crate::SourceFormat;

/// The top-level keys that tell a `.plan` from aloft's JSON.
#[derive(Deserialize)]
struct Probe {
    #[serde(rename = "fileType")]
    file_type: Option<IgnoredAny>,
    mission: Option<IgnoredAny>,
}

/// The format of `text`.
pub fn detect(text: &str) -> SourceFormat {
    let t = text.trim_start_matches('\u{feff}').trim_start();
    if t.starts_with("QGC WPL") {
        return SourceFormat::QgcWpl;
    }
    if !t.starts_with('{') {
        return SourceFormat::AloftToml;
    }
    match serde_json::from_str::<Probe>(t) {
        Ok(p) if p.file_type.is_some() || p.mission.is_some() => SourceFormat::QgcPlan,
        Ok(_) => SourceFormat::AloftJson,
        // Not valid JSON: a plan when it names the plan's key, so its reader says where it breaks.
        Err(_) if t.contains("\"fileType\"") => SourceFormat::QgcPlan,
        Err(_) => SourceFormat::AloftJson,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_are_told_by_content() {
        assert_eq!(detect("QGC WPL 110\r\n0\t1"), SourceFormat::QgcWpl);
        assert_eq!(detect("\u{feff}  QGC WPL 120\n"), SourceFormat::QgcWpl);
        assert_eq!(
            detect(r#"{"fileType": "Plan", "mission": {}}"#),
            SourceFormat::QgcPlan
        );
        assert_eq!(detect(r#"{"fileType": "GeoFence"}"#), SourceFormat::QgcPlan);
        assert_eq!(
            detect(r#"{"fileType": "Plan", "mission": "#),
            SourceFormat::QgcPlan
        );
        assert_eq!(
            detect(r#"{"name": "m", "segment": [], "description": "fileType"}"#),
            SourceFormat::AloftJson
        );
        assert_eq!(
            detect("name = \"m\"\n[[segment]]\n"),
            SourceFormat::AloftToml
        );
        assert_eq!(detect(""), SourceFormat::AloftToml);
    }
}
