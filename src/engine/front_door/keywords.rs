//! Options by keyword (Python's `aloft.mission(payload_kg=0.5)`), parsed with the command
//! line's own description of the options ([`crate::engine::front_door::flags`]): the same names, defaults, ranges
//! and pairs, so the two cannot drift. Only the words of the messages differ: a keyword is named
//! `'payload_kg' of aloft.mission`, as the caller wrote it.

use std::ffi::OsString;

use clap::error::{ContextKind, ContextValue, ErrorKind};
use clap::{Arg, ArgAction, Args, Command, FromArgMatches};

use crate::error::Error;

/// An option group that can be parsed from keywords (every group of [`crate::engine::front_door::flags`]).
pub trait FlagGroup: Args + FromArgMatches {}

impl<T: Args + FromArgMatches> FlagGroup for T {}

/// The value of one keyword, as the caller's language gave it.
#[derive(Debug, Clone, PartialEq)]
pub enum Keyword {
    /// `True` or `False`: a switch (`no_ground_effect=True` is `--no-ground-effect`).
    Switch(bool),
    /// One value, as text (numbers in their shortest round-trip form).
    One(OsString),
    /// Several values (a list or tuple), for options that take several.
    Many(Vec<OsString>),
}

/// A keyword's value in messages.
fn shown(value: &Keyword) -> String {
    let one = |v: &OsString| format!("'{}'", v.to_string_lossy());
    match value {
        Keyword::Switch(true) => "True".to_string(),
        Keyword::Switch(false) => "False".to_string(),
        Keyword::One(v) => one(v),
        Keyword::Many(vs) => format!("[{}]", vs.iter().map(one).collect::<Vec<_>>().join(", ")),
    }
}

/// The keyword of an option: its long name in snake_case.
fn keyword_of(arg: &Arg) -> Option<String> {
    arg.get_long().map(|l| l.replace('-', "_"))
}

/// The keywords of the options of `T` (what a caller may name), sorted, without `reserved`
/// (the options a function takes positionally).
pub fn keywords<T: FlagGroup>(reserved: &[&str]) -> Vec<String> {
    let cmd = T::augment_args(Command::new("aloft"));
    let mut names: Vec<String> = cmd
        .get_arguments()
        .filter(|a| !a.is_hide_set())
        .filter_map(keyword_of)
        .filter(|k| !reserved.contains(&k.as_str()))
        .collect();
    names.sort_unstable();
    names
}

/// Words of an option's value name (`|` between them) that say it names a file (`--vehicle <NAME|FILE>`,
/// `--wind-field <CSV>`, `--profile <PROFILE>`: a profile may be a column-map file).
const FILE_VALUE_WORDS: [&str; 6] = ["FILE", "CSV", "TOML", "LOG", "MCAP", "PROFILE"];

/// The keywords of the options of `T` whose value may name a file to read (or write): a caller
/// that answers others (`aloft serve`) resolves or refuses each, so that no request names a
/// file of the server's ([`crate::engine::front_door::flags`] gives every such option a value name that says so).
pub fn file_keywords<T: FlagGroup>() -> Vec<String> {
    let cmd = T::augment_args(Command::new("aloft"));
    let mut names: Vec<String> = cmd
        .get_arguments()
        .filter(|a| !a.is_hide_set())
        .filter(|a| {
            a.get_value_names().is_some_and(|names| {
                names.iter().any(|n| {
                    n.split(['|', '['])
                        .any(|word| FILE_VALUE_WORDS.contains(&word))
                })
            })
        })
        .filter_map(keyword_of)
        .collect();
    names.sort_unstable();
    names
}

/// Parse `keywords` (and the `positional` options, given by the function's own arguments) into
/// `T`, as the command line parses its flags. `function` names the caller in messages
/// as its user wrote it (`aloft.mission` in Python, `POST /api/mission` for `aloft serve`).
///
/// # Errors
/// [`Error::Keyword`] naming the keyword: unknown (with the known ones), a value that is not
/// of its kind or out of its range (with the command line's reason), a missing partner
/// (`'wind_speed' of aloft.mission needs 'wind_from'`) or a conflict.
pub fn parse_keywords<T: FlagGroup>(
    function: &str,
    positional: &[(&str, Keyword)],
    keywords_given: &[(String, Keyword)],
) -> Result<T, Error> {
    let reserved: Vec<&str> = positional.iter().map(|(k, _)| *k).collect();
    let cmd = T::augment_args(Command::new("aloft").no_binary_name(true));
    let mut argv: Vec<OsString> = Vec::new();
    let all = positional
        .iter()
        .map(|(k, v)| (k.to_string(), v.clone(), true))
        .chain(
            keywords_given
                .iter()
                .map(|(k, v)| (k.clone(), v.clone(), false)),
        );
    for (key, value, is_positional) in all {
        let arg = cmd
            .get_arguments()
            .find(|a| keyword_of(a).as_deref() == Some(key.as_str()) && !a.is_hide_set())
            .filter(|_| is_positional || !reserved.contains(&key.as_str()));
        let Some(arg) = arg else {
            return Err(keyword_error(format!(
                "unknown option '{key}' for {function}; known options: {}",
                keywords::<T>(&reserved).join(", ")
            )));
        };
        push_flag(&mut argv, arg, &key, &value, function)?;
    }
    let matches = cmd
        .clone()
        .try_get_matches_from(argv.clone())
        .map_err(|e| translate(&e, &cmd, &argv, function))?;
    T::from_arg_matches(&matches).map_err(|e| keyword_error(format!("{function}: {e}")))
}

fn keyword_error(message: String) -> Error {
    Error::Keyword { message }
}

/// The flag (and its values) of one keyword.
fn push_flag(
    argv: &mut Vec<OsString>,
    arg: &Arg,
    key: &str,
    value: &Keyword,
    function: &str,
) -> Result<(), Error> {
    let long = format!("--{}", arg.get_long().unwrap_or(key));
    let switch = matches!(arg.get_action(), ArgAction::SetTrue);
    let invalid = |why: &str| {
        keyword_error(format!(
            "invalid value {} for '{key}' of {function}: {why}",
            shown(value)
        ))
    };
    match (value, switch) {
        (Keyword::Switch(on), true) => {
            if *on {
                argv.push(long.into());
            }
        }
        (_, true) => return Err(invalid("not True or False")),
        (Keyword::Switch(_), false) => return Err(invalid("expected a value, not True or False")),
        (Keyword::One(v), false) => argv.push(with_value(&long, v)),
        (Keyword::Many(vs), false) => {
            let takes_many = matches!(arg.get_action(), ArgAction::Append)
                || arg.get_num_args().is_some_and(|n| n.max_values() > 1);
            if takes_many {
                argv.extend(vs.iter().map(|v| with_value(&long, v)));
            } else if let Some(joined) = joined_by_colons(arg, vs) {
                // A value written `START:STOP:STEP` may be given as its parts.
                argv.push(with_value(&long, &joined));
            } else {
                return Err(invalid("expected one value, not a list"));
            }
        }
    }
    Ok(())
}

/// The parts of a value whose name is written with colons (`START:STOP:STEP`), joined so.
fn joined_by_colons(arg: &Arg, parts: &[OsString]) -> Option<OsString> {
    let names = arg.get_value_names()?;
    if !names.iter().any(|n| n.contains(':')) {
        return None;
    }
    let mut joined = OsString::new();
    for (i, p) in parts.iter().enumerate() {
        if i > 0 {
            joined.push(":");
        }
        joined.push(p);
    }
    Some(joined)
}

/// `--name=value` (so that values starting with `-` stay values).
fn with_value(long: &str, value: &OsString) -> OsString {
    let mut s = OsString::from(format!("{long}="));
    s.push(value);
    s
}

/// The keyword of a flag as clap shows it (`--wind-speed <M/S>` is `wind_speed`).
fn keyword_in(shown_flag: &str) -> String {
    shown_flag
        .trim_start_matches('-')
        .split([' ', '='])
        .next()
        .unwrap_or(shown_flag)
        .replace('-', "_")
}

fn context_strings(e: &clap::Error, kind: ContextKind) -> Vec<String> {
    match e.get(kind) {
        Some(ContextValue::String(s)) => vec![s.clone()],
        Some(ContextValue::Strings(v)) => v.clone(),
        _ => Vec::new(),
    }
}

/// A parser's refusal in the caller's words.
fn translate(e: &clap::Error, cmd: &Command, argv: &[OsString], function: &str) -> Error {
    let arg = context_strings(e, ContextKind::InvalidArg)
        .first()
        .map(|s| keyword_in(s))
        .unwrap_or_default();
    let value = context_strings(e, ContextKind::InvalidValue)
        .first()
        .cloned()
        .unwrap_or_default();
    let message = match e.kind() {
        ErrorKind::InvalidValue => {
            let valid = context_strings(e, ContextKind::ValidValue)
                .iter()
                .map(|v| format!("'{v}'"))
                .collect::<Vec<_>>()
                .join(", ");
            format!("invalid value '{value}' for '{arg}' of {function}: expected one of {valid}")
        }
        ErrorKind::ValueValidation => {
            let why = std::error::Error::source(e)
                .map(|s| aloft_core::one_line(&s.to_string()))
                .unwrap_or_else(|| "out of range".to_string());
            format!("invalid value '{value}' for '{arg}' of {function}: {why}")
        }
        ErrorKind::ArgumentConflict => {
            let other = context_strings(e, ContextKind::PriorArg)
                .first()
                .map(|s| keyword_in(s))
                .unwrap_or_default();
            format!("the option '{arg}' of {function} cannot be used with '{other}'")
        }
        ErrorKind::MissingRequiredArgument => {
            let missing: Vec<String> = context_strings(e, ContextKind::InvalidArg)
                .iter()
                .map(|s| keyword_in(s))
                .collect();
            missing_partner(cmd, argv, function, &missing)
        }
        _ => format!(
            "{function}: {}",
            aloft_core::one_line(&e.to_string()).trim_start_matches("error: ")
        ),
    };
    keyword_error(message)
}

/// Which given option needs the missing one: each flag given is parsed alone, and the first
/// that misses the same option is named; when several options need it, they are listed.
fn missing_partner(cmd: &Command, argv: &[OsString], function: &str, missing: &[String]) -> String {
    let Some(first) = missing.first() else {
        return format!("{function}: a required option is missing");
    };
    let misses_first = |flag: &OsString| {
        cmd.clone()
            .try_get_matches_from([flag.clone()])
            .err()
            .filter(|e| e.kind() == ErrorKind::MissingRequiredArgument)
            .is_some_and(|e| {
                context_strings(&e, ContextKind::InvalidArg)
                    .iter()
                    .any(|s| keyword_in(s) == *first)
            })
    };
    let needing: Vec<String> = argv
        .iter()
        .filter(|f| misses_first(f))
        .map(|f| keyword_in(&f.to_string_lossy()))
        .collect();
    let all = needers(cmd, first);
    let also = if all.len() > 1 {
        format!(" (the options that need '{first}': {})", all.join(", "))
    } else {
        String::new()
    };
    match needing.as_slice() {
        [] => format!("{function} needs '{first}'{also}"),
        [one] => format!("'{one}' of {function} needs '{first}'{also}"),
        many => format!(
            "the options {} of {function} need '{first}'",
            many.iter()
                .map(|k| format!("'{k}'"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// Every option of `cmd` that needs `first` (each given alone, with a value it takes).
fn needers(cmd: &Command, first: &str) -> Vec<String> {
    let mut out: Vec<String> = cmd
        .get_arguments()
        .filter(|a| !a.is_hide_set())
        .filter_map(|a| {
            let long = format!("--{}", a.get_long()?);
            let flag: OsString = if matches!(a.get_action(), ArgAction::SetTrue) {
                long.into()
            } else {
                let value = a
                    .get_default_values()
                    .first()
                    .map(|v| v.to_os_string())
                    .or_else(|| a.get_possible_values().first().map(|p| p.get_name().into()))
                    .unwrap_or_else(|| "1".into());
                with_value(&long, &value)
            };
            let e = cmd.clone().try_get_matches_from([flag]).err()?;
            let needs = e.kind() == ErrorKind::MissingRequiredArgument
                && context_strings(&e, ContextKind::InvalidArg)
                    .iter()
                    .any(|s| keyword_in(s) == first);
            needs.then(|| keyword_of(a)).flatten()
        })
        .collect();
    out.sort_unstable();
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::front_door::flags::{
        EnduranceFlags, FitFlags, LiveFlags, LogInfoFlags, MissionScenarioFlags, PowerModelFlags,
        ValidateFlags,
    };

    /// Every option that names a file is known as one: a server resolves or refuses each
    /// (issue 32: `wind_field=/etc/passwd` was read and quoted). The lists are written out here,
    /// from the options' help, so that a new file option without a value name that says so
    /// fails this test rather than passing through.
    #[test]
    fn every_option_that_names_a_file_is_known_as_one() {
        assert_eq!(
            file_keywords::<MissionScenarioFlags>(),
            ["vehicle", "wind_field"]
        );
        assert_eq!(file_keywords::<EnduranceFlags>(), ["vehicle"]);
        assert_eq!(file_keywords::<PowerModelFlags>(), ["vehicle"]);
        assert_eq!(file_keywords::<LogInfoFlags>(), ["profile"]);
        assert_eq!(
            file_keywords::<FitFlags>(),
            ["log", "output", "profile", "vehicle_template"]
        );
        assert_eq!(
            file_keywords::<ValidateFlags>(),
            ["log", "profile", "vehicle"]
        );
        assert_eq!(
            file_keywords::<LiveFlags>(),
            ["mission", "profile", "replay", "tlog", "vehicle"]
        );
    }
}
