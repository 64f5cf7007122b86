//! A mission to plan: the mission file (any of the four formats, recognised from its content) or
//! the built-in demonstration, with where it came from and its route figures.

use std::path::Path;

use aloft_missions::{route_figures, ReadOptions, RouteFigures, SourceFormat};

use crate::engine::missions::ground::{Frame, Ground};
use aloft_planner::MissionSpec;

use crate::engine::basics::files::read_text_file;
use crate::error::Error;

/// The built-in demonstration mission (identical to `fixtures/missions/demo-survey.toml`): four
/// survey lines and a two-lap orbit in a 6 m/s breeze.
pub const DEMO_MISSION: &str = include_str!("../../../fixtures/missions/demo-survey.toml");

/// Origin the CLI gives the built-in demonstration mission (its name when the file has none).
pub const DEMO_ORIGIN: &str = "built-in demo";

/// The stem of the files `aloft plan` writes for the built-in demo (its fixture's name).
pub const DEMO_FILE_STEM: &str = "demo-survey";

/// A mission to plan: the parsed mission file, where it came from, and its route figures (the
/// file's own geometry, with what the reader of a planner file noticed).
#[derive(Debug, Clone, PartialEq)]
pub struct Mission {
    spec: MissionSpec,
    origin: String,
    route: RouteFigures,
    /// The planner file as read (`.plan`, `.waypoints`): what `aloft plan` needs to write it
    /// again (its home, items, a `.plan`'s header and surveys, the flying order).
    kept: Option<Box<aloft_missions::Imported>>,
    /// What a planner file was read from, to read it again with other options.
    source: Option<PlannerSource>,
    /// The options it was read with.
    read: ReadOptions,
}

/// What a planner file was read from.
#[derive(Debug, Clone, PartialEq)]
enum PlannerSource {
    /// The file's text.
    Text(std::sync::Arc<str>),
    /// A link's or a log's mission items.
    Items(std::sync::Arc<[aloft_logs::telemetry::MissionItem]>),
}

impl Mission {
    /// The mission file at `path` in any of the four formats, recognised from its content (see
    /// [`Mission::from_text`]), or the built-in demonstration mission when `path` is `None`.
    ///
    /// # Errors
    /// [`Error::Io`] when the file cannot be read, [`Error::MissionFormat`] or
    /// [`Error::MissionImport`] when it does not parse.
    pub fn load(path: Option<&Path>) -> Result<Self, Error> {
        match path {
            None => Ok(Self::demo()),
            Some(p) => {
                let text = read_text_file(p, "mission file")?;
                Self::from_text(&text, &p.display().to_string())
            }
        }
    }

    /// The built-in demonstration mission ([`DEMO_MISSION`]).
    pub fn demo() -> Self {
        // Parsed once per call; the text is compiled in and checked by a unit test.
        // Unreachable failure for the committed fixture; an empty mission fails cleanly at
        // planning.
        let spec = MissionSpec::from_toml_str(DEMO_MISSION).unwrap_or_default();
        Self::of_spec(spec, DEMO_ORIGIN, SourceFormat::AloftToml)
    }

    /// An aloft mission spec from `format`, with its route figures.
    pub(crate) fn of_spec(spec: MissionSpec, origin: &str, format: SourceFormat) -> Self {
        Self {
            route: route_figures(&spec, format, Vec::new()),
            spec,
            origin: origin.to_string(),
            kept: None,
            source: None,
            read: ReadOptions::default(),
        }
    }

    /// A mission from TOML text (the mission file format); `origin` names it in messages and is
    /// the mission's name in the summary when the file has no `name`.
    ///
    /// # Errors
    /// [`Error::MissionFormat`] with the parser's line, column and key.
    pub fn from_toml(text: &str, origin: &str) -> Result<Self, Error> {
        check_size(text, origin)?;
        let spec = MissionSpec::from_toml_str(text).map_err(|e| Error::MissionFormat {
            origin: origin.to_string(),
            message: match e {
                aloft_planner::PlannerError::MissionFormat { message } => message,
                other => other.to_string(),
            },
        })?;
        Ok(Self::of_spec(spec, origin, SourceFormat::AloftToml))
    }

    /// A mission from JSON text: the mission file's structure, e.g.
    /// `{"name": "m", "segment": [{"kind": "take-off", "altitude_m": 20, "climb_rate_mps": 2}, ...]}`.
    ///
    /// # Errors
    /// [`Error::MissionFormat`] with the parser's line, column and key.
    pub fn from_json(text: &str, origin: &str) -> Result<Self, Error> {
        check_size(text, origin)?;
        let spec: MissionSpec = serde_json::from_str(text).map_err(|e| Error::MissionFormat {
            origin: origin.to_string(),
            message: aloft_core::file_message(&e.to_string()),
        })?;
        Ok(Self::of_spec(spec, origin, SourceFormat::AloftJson))
    }

    /// A mission from a planner file: a QGroundControl `.plan` or a `QGC WPL 110` `.waypoints`
    /// (see the `aloft-missions` crate for what each MAVLink command flies). Every segment
    /// carries the operator's item number; the route figures carry the reader's warnings.
    ///
    /// # Errors
    /// [`Error::MissionImport`] naming the item (or row, or line) and the command or key.
    pub fn from_planner_file(text: &str, origin: &str) -> Result<Self, Error> {
        check_size(text, origin)?;
        let source = PlannerSource::Text(text.into());
        Self::read(source, origin, ReadOptions::default())
    }

    /// A mission as a MAVLink link or log carries it (MISSION_ITEM_INT, DataFlash `CMD`; item 0
    /// is home on ArduPilot), flown as its `.waypoints` file would be; `origin` names it.
    ///
    /// # Errors
    /// [`Error::MissionImport`] naming the item and the command.
    pub fn from_items(
        items: &[aloft_logs::telemetry::MissionItem],
        origin: &str,
    ) -> Result<Self, Error> {
        Self::read(
            PlannerSource::Items(items.into()),
            origin,
            ReadOptions::default(),
        )
    }

    /// The planner file read from `source` with `options`, or its error naming `origin`.
    fn read(source: PlannerSource, origin: &str, options: ReadOptions) -> Result<Self, Error> {
        let imported = match &source {
            PlannerSource::Text(text) => aloft_missions::import_with(text, options),
            PlannerSource::Items(items) => aloft_missions::read_items_with(items, options),
        }
        .map_err(|source| Error::MissionImport {
            origin: origin.to_string(),
            source,
        })?;
        Ok(Self {
            spec: imported.spec.clone(),
            origin: origin.to_string(),
            route: imported.route.clone(),
            kept: Some(Box::new(imported)),
            source: Some(source),
            read: options,
        })
    }

    /// The options the mission was read with.
    pub fn read_options(&self) -> ReadOptions {
        self.read
    }

    /// As [`Mission::from_text`], a planner file read with `options`.
    ///
    /// # Errors
    /// As [`Mission::from_text`].
    pub fn from_text_with(text: &str, origin: &str, options: ReadOptions) -> Result<Self, Error> {
        let mission = Self::from_text(text, origin)?;
        match options == ReadOptions::default() {
            true => Ok(mission),
            false => mission.read_with(options),
        }
    }

    /// The mission read again with `options` (a planner file; any other mission as it is).
    ///
    /// # Errors
    /// As the reader's with those options.
    pub fn read_with(&self, options: ReadOptions) -> Result<Self, Error> {
        match &self.source {
            Some(source) => Self::read(source.clone(), &self.origin, options),
            None => Ok(self.clone()),
        }
    }

    /// Any of the four formats, recognised from the content (not the file name): a
    /// QGroundControl `.plan` (JSON with a `fileType` key), a `.waypoints` file (`QGC WPL`),
    /// an aloft mission in JSON (another JSON object) or in TOML (anything else).
    ///
    /// # Errors
    /// As [`Mission::from_planner_file`], [`Mission::from_json`] or [`Mission::from_toml`].
    pub fn from_text(text: &str, origin: &str) -> Result<Self, Error> {
        check_size(text, origin)?;
        match aloft_missions::detect(text) {
            SourceFormat::QgcPlan | SourceFormat::QgcWpl | SourceFormat::MavlinkItems => {
                Self::from_planner_file(text, origin)
            }
            SourceFormat::AloftJson => Self::from_json(text, origin),
            SourceFormat::AloftToml => Self::from_toml(text, origin),
        }
    }

    /// The mission as JSON text that [`Mission::from_json`] reads back.
    ///
    /// # Errors
    /// [`Error::OptionsFormat`] if serialisation fails (non-finite numbers cannot occur in a
    /// parsed mission, so in practice it does not).
    pub fn to_json(&self) -> Result<String, Error> {
        serde_json::to_string(&self.spec).map_err(|e| Error::OptionsFormat {
            what: "mission",
            message: e.to_string(),
        })
    }

    /// The mission flown over `ground`: a planner file read again knowing the terrain, the legs
    /// of its terrain-frame items (frame 10/11) followed over the ground, its landings on the
    /// ground where they are; the route figures counted on that (its climbs and descents over
    /// the ground), the segment ranges of the items flown moved with the legs added.
    ///
    /// # Errors
    /// The reader's, the tiles' (no tile or a void under the route).
    pub(in crate::engine) fn over_ground(
        &self,
        ground: &Ground<'_>,
        rtl_altitude_m: Option<f64>,
    ) -> Result<Self, Error> {
        let mut read = self.read;
        read.terrain = true;
        let mut mission = self.read_with(read)?;
        let mut frames = vec![Frame::Relative; mission.spec.segments.len()];
        if let Some(kept) = &mission.kept {
            for f in &kept.flown {
                let frame = kept
                    .items
                    .get(f.item)
                    .map_or(Frame::Relative, |i| Frame::of_mavlink(i.frame));
                for slot in frames
                    .iter_mut()
                    .take(f.segments.end)
                    .skip(f.segments.start)
                {
                    *slot = frame;
                }
            }
        }
        let (spec, made) = ground.follow(&mission.spec, &frames, rtl_altitude_m)?;
        let reader_warnings = mission.kept.as_ref().map(|k| k.warnings.clone());
        if let Some(kept) = &mut mission.kept {
            let starts: Vec<usize> = std::iter::once(0)
                .chain(made.iter().scan(0, |sum, n| {
                    *sum += n;
                    Some(*sum)
                }))
                .collect();
            for f in &mut kept.flown {
                let at = |k: usize| starts.get(k).copied().unwrap_or(spec.segments.len());
                f.segments = at(f.segments.start)..at(f.segments.end);
            }
            kept.spec = spec.clone();
        }
        let mut route = route_figures(
            &spec,
            mission.route.source_format,
            reader_warnings.unwrap_or_default(),
        );
        route.items = mission.route.items;
        route.warnings.extend(ground.notes.iter().cloned());
        mission.route = route;
        mission.spec = spec;
        Ok(mission)
    }

    /// The planner file as read, to be written again (none for aloft's own formats).
    pub fn kept(&self) -> Option<&aloft_missions::Imported> {
        self.kept.as_deref()
    }

    /// The parsed mission file.
    pub fn spec(&self) -> &MissionSpec {
        &self.spec
    }

    /// Where it came from.
    pub fn origin(&self) -> &str {
        &self.origin
    }

    /// The route figures: the file's own geometry, its format and the reader's warnings.
    pub fn route(&self) -> &RouteFigures {
        &self.route
    }

    /// The name the summary reports: the file's `name`, else the origin.
    pub fn display_name(&self) -> &str {
        if self.spec.name.is_empty() {
            &self.origin
        } else {
            &self.spec.name
        }
    }
}

/// A mission text within the values a parser may hold ([`aloft_core::MAX_TEXT_VALUES`]).
///
/// # Errors
/// [`Error::MissionFormat`] naming the count.
fn check_size(text: &str, origin: &str) -> Result<(), Error> {
    aloft_core::check_value_count(text).map_err(|count| Error::MissionFormat {
        origin: origin.to_string(),
        message: aloft_core::too_many_values(count),
    })
}
