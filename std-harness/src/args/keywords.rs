//! A request built from typed keyword values instead of flag strings (issue 76): what the Python
//! package hands over (`render(volume, size=(256, 256), lod=0, slicing="image")`). Each keyword is
//! a flag's name with underscores (`eye_distance` is `--eye-distance`, `type` or `sample_type` is
//! `--type`), and its [`Value`] is checked by the same typed check the flag's text parser ends in
//! (`parse.rs`: [`size`], [`positive`], [`level`], …),
//! so a keyword and a flag accept the same values and refuse the rest with the same reason. The
//! request then goes through the same resolution as the command line's (`resolve.rs`), where the
//! rules between fields live.
//!
//! The defaults are the command line's, read from its one declaration ([`defaults`]: clap's
//! defaults for an empty command line), so a keyword left out means what a flag left out means.

use super::{
    depth_phases, factor, finite_f32, fov, grid_side, level, min_radius, parse_background,
    parse_cull, parse_lod, parse_sample_type, parse_supersample, parse_view, positive, size,
    spacing, threshold, RenderArgs,
};
use crate::CliError;
use clap::ValueEnum;
use std::path::PathBuf;

/// A keyword's value as a program hands it over: a Python `bool`, `int`, `float`, `str` (or
/// path), or a tuple or list of them. No value is a flag's text: a number is a number.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    Bool(bool),
    Int(i64),
    Float(f64),
    Text(String),
    List(Vec<Value>),
}

impl std::fmt::Display for Value {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Value::Bool(b) => write!(f, "{}", if *b { "True" } else { "False" }),
            Value::Int(i) => write!(f, "{i}"),
            Value::Float(x) => write!(f, "{x}"),
            Value::Text(t) => write!(f, "{t:?}"),
            Value::List(v) => {
                let items: Vec<String> = v.iter().map(Value::to_string).collect();
                write!(f, "({})", items.join(", "))
            }
        }
    }
}

/// A request that takes keywords: `render`'s [`RenderArgs`], and the commands that flatten it
/// (`verify`, `bench`) with their own keywords first.
pub trait Keywords: clap::Args + clap::FromArgMatches {
    /// Sets the field keyword `key` names to `value`, checked as its flag's value is; an unknown
    /// keyword or a value of the wrong kind is a typed error naming both.
    fn set(&mut self, key: &str, value: &Value) -> Result<(), CliError>;
}

/// The command line's defaults for `T` (what an empty command line gives: clap reads them from
/// the one declaration the flags have).
pub fn defaults<T: clap::Args + clap::FromArgMatches>() -> T {
    let command = T::augment_args(clap::Command::new("footprint").no_binary_name(true));
    let matches = command
        .try_get_matches_from(std::iter::empty::<&str>())
        .expect("every flag of a request has a default or is optional");
    T::from_arg_matches(&matches).expect("the defaults are values of their fields")
}

/// `T`'s defaults with each keyword of `pairs` set in turn.
pub fn from_keywords<'a, T>(
    pairs: impl IntoIterator<Item = (&'a str, &'a Value)>,
) -> Result<T, CliError>
where
    T: Keywords,
{
    let mut request: T = defaults();
    for (key, value) in pairs {
        request.set(key, value)?;
    }
    Ok(request)
}

/// The typed error for keyword `key`: `why` about `value`.
pub fn refused(key: &str, value: &Value, why: impl std::fmt::Display) -> CliError {
    CliError::input(format!("{key}={value}: {why}"))
}

/// `value` as a number (an int or a float).
pub fn number(key: &str, value: &Value) -> Result<f64, CliError> {
    match value {
        Value::Int(i) => Ok(*i as f64),
        Value::Float(x) => Ok(*x),
        _ => Err(refused(key, value, "expected a number")),
    }
}

/// `value` as a finite number.
pub fn finite(key: &str, value: &Value) -> Result<f64, CliError> {
    let x = number(key, value)?;
    if x.is_finite() {
        Ok(x)
    } else {
        Err(refused(key, value, "not finite"))
    }
}

/// `value` as a finite f32 passed through `check`.
fn f32_checked(
    key: &str,
    value: &Value,
    check: impl Fn(f32) -> Result<f32, String>,
) -> Result<f32, CliError> {
    let x = finite_f32(finite(key, value)?).map_err(|e| refused(key, value, e))?;
    check(x).map_err(|e| refused(key, value, e))
}

/// `value` as a whole number ≥ 0 (an int; a float is refused, as `2.5` is as a flag).
pub fn whole(key: &str, value: &Value) -> Result<u64, CliError> {
    match value {
        Value::Int(i) if *i >= 0 => Ok(*i as u64),
        _ => Err(refused(key, value, "expected a whole number ≥ 0")),
    }
}

/// `value` as text (a string or a path).
pub fn text<'a>(key: &str, value: &'a Value) -> Result<&'a str, CliError> {
    match value {
        Value::Text(t) => Ok(t),
        _ => Err(refused(key, value, "expected a string")),
    }
}

/// `value` as exactly `N` items, each converted by `item`.
fn items<const N: usize, T: Copy + Default>(
    key: &str,
    value: &Value,
    item: impl Fn(&Value) -> Result<T, CliError>,
) -> Result<[T; N], CliError> {
    match value {
        Value::List(v) if v.len() == N => {
            let mut out = [T::default(); N];
            for (o, x) in out.iter_mut().zip(v) {
                *o = item(x)?;
            }
            Ok(out)
        }
        _ => Err(refused(key, value, format!("expected {N} numbers"))),
    }
}

/// `value` as one of a flag's choices (its name, as on the command line).
pub fn choice<E: ValueEnum>(key: &str, value: &Value) -> Result<E, CliError> {
    let t = text(key, value)?;
    E::from_str(t, false).map_err(|_| {
        let names: Vec<String> = E::value_variants()
            .iter()
            .filter_map(|v| v.to_possible_value().map(|p| p.get_name().to_string()))
            .collect();
        refused(key, value, format!("expected one of {}", names.join(", ")))
    })
}

/// A keyword that is a number or one word (`lod=0` or `lod="auto"`): `number` for a whole
/// number, `word` (the flag's text parser) for text.
fn number_or_word<T>(
    key: &str,
    value: &Value,
    number: impl Fn(u64) -> Result<T, String>,
    word: impl Fn(&str) -> Result<T, String>,
) -> Result<T, CliError> {
    match value {
        Value::Text(t) => word(t).map_err(|e| refused(key, value, e)),
        _ => number(whole(key, value)?).map_err(|e| refused(key, value, e)),
    }
}

fn path(key: &str, value: &Value) -> Result<PathBuf, CliError> {
    text(key, value).map(PathBuf::from)
}

impl Keywords for RenderArgs {
    fn set(&mut self, key: &str, v: &Value) -> Result<(), CliError> {
        let err = |e: String| refused(key, v, e);
        let f64s = |v: &Value| finite(key, v);
        let f32s = |v: &Value| f32_checked(key, v, Ok);
        let fa = &mut self.footprint;
        match key {
            "volume" => self.volume = Some(path(key, v)?),
            "size" => {
                self.size = match v {
                    Value::Text(t) => super::parse_size(t).map_err(err)?,
                    _ => size(items::<2, u64>(key, v, |x| whole(key, x))?).map_err(err)?,
                }
            }
            "view" => {
                self.view = match v {
                    Value::Text(t) => parse_view(t).map_err(err)?,
                    _ => items::<3, f32>(key, v, f32s)?,
                }
            }
            "zoom" => self.zoom = f32_checked(key, v, positive)?,
            "view_matrix" => self.view_matrix = Some(items::<9, f32>(key, v, f32s)?),
            "perspective" => self.perspective = Some(f32_checked(key, v, fov)?),
            "eye_distance" => self.eye_distance = Some(f32_checked(key, v, positive)?),
            // One transfer function, or one per component.
            "tf" => {
                self.tf = match v {
                    Value::List(l) => l
                        .iter()
                        .map(|x| text(key, x).map(str::to_string))
                        .collect::<Result<_, _>>()?,
                    _ => vec![text(key, v)?.to_string()],
                }
            }
            "labels" => self.labels = Some(text(key, v)?.to_string()),
            "window" => self.window = Some(items::<2, f64>(key, v, f64s)?),
            "clip" => {
                // One plane (four numbers) or a sequence of planes.
                let plane = |x: &Value| {
                    let [a, b, c, d] = items::<4, f64>(key, x, f64s)?;
                    crate::scene::ClipPlane::new([a, b, c], d).map_err(err)
                };
                self.clip = match v {
                    Value::Text(t) => vec![super::parse_clip(t).map_err(err)?],
                    Value::List(l) if l.iter().all(|x| matches!(x, Value::List(_))) => {
                        l.iter().map(plane).collect::<Result<_, _>>()?
                    }
                    _ => vec![plane(v)?],
                }
            }
            "crop" => {
                self.crop = Some(match v {
                    Value::Text(t) => super::parse_crop(t).map_err(err)?,
                    _ => {
                        let index = |x: &Value| whole(key, x).map(|n| n as usize);
                        let pair = |x: &Value| items::<2, usize>(key, x, index);
                        crate::scene::Crop::new(items::<3, [usize; 2]>(key, v, pair)?)
                            .map_err(err)?
                    }
                })
            }
            "shading" => self.shading = text(key, v)?.to_string(),
            "background" => self.background = parse_background(text(key, v)?).map_err(err)?,
            "gamma" => self.gamma = choice(key, v)?,
            "depth" => {
                self.depth = match whole(key, v)? {
                    8 => 8,
                    16 => 16,
                    _ => return Err(err("expected 8 or 16 bits".into())),
                }
            }
            "json" => self.json = Some(path(key, v)?),
            "out" => self.out = Some(path(key, v)?),
            "array" => self.array = Some(text(key, v)?.to_string()),
            "scene_size" => self.scene_size = grid_side(whole(key, v)?).map_err(err)?,
            "field_size" => self.field_size = grid_side(whole(key, v)?).map_err(err)?,
            "stream" => self.stream = Some(path(key, v)?),
            "dims" => {
                let dims = items::<3, u64>(key, v, |x| whole(key, x))?;
                if dims.contains(&0) {
                    return Err(err("each of X, Y, Z is at least 1 voxel".into()));
                }
                self.dims = Some(dims.map(|n| n as usize));
            }
            "type" | "sample_type" => {
                self.sample_type = Some(parse_sample_type(text(key, v)?).map_err(err)?)
            }
            "endian" => self.endian = choice(key, v)?,
            "spacing" => self.spacing = spacing(items::<3, f32>(key, v, f32s)?).map_err(err)?,
            "kernel" => fa.kernel = text(key, v)?.to_string(),
            "table" => fa.table = whole(key, v)? as usize,
            "table_file" => fa.table_file = Some(path(key, v)?),
            "lookup" => fa.lookup = choice(key, v)?,
            "method" => fa.method = choice(key, v)?,
            "min_radius" => fa.min_radius = f32_checked(key, v, min_radius)?,
            "paper_cheat" => fa.paper_cheat = f32s(v)?,
            _ => return self.set_method(key, v),
        }
        Ok(())
    }
}

impl RenderArgs {
    /// The Method, Resolution and Speed-and-quality keywords ([`Keywords::set`] for the rest).
    fn set_method(&mut self, key: &str, v: &Value) -> Result<(), CliError> {
        let err = |e: String| refused(key, v, e);
        let supersample = |v: &Value| number_or_word(key, v, factor, parse_supersample);
        match key {
            "accum" => self.accum = choice(key, v)?,
            "slicing" => self.slicing = Some(choice(key, v)?),
            "slab" => self.slab = f32_checked(key, v, positive)?,
            "absorption" => self.absorption = choice(key, v)?,
            "classification" => self.classification = choice(key, v)?,
            "blend" => self.blend = choice(key, v)?,
            "reconstruction" => self.reconstruction = choice(key, v)?,
            "slab_post" => self.slab_post = Some(f32_checked(key, v, positive)?),
            "value_subsample" => self.value_subsample = supersample(v)?,
            "phases" => self.phases = whole(key, v)? as usize,
            "depth_phases" => self.depth_phases = depth_phases(whole(key, v)?).map_err(err)?,
            "phase_lookup" => self.phase_lookup = choice(key, v)?,
            "order" => self.order = Some(choice(key, v)?),
            "supersample" => self.supersample = supersample(v)?,
            "subsample" => self.subsample = Some(supersample(v)?),
            "lod" => self.lod = number_or_word(key, v, level, parse_lod)?,
            "refine" => self.refine = Some(f32_checked(key, v, threshold)?),
            "refine_sheets" => match v {
                Value::Bool(b) => self.refine_sheets = *b,
                _ => return Err(err("expected True or False".into())),
            },
            "threads" => self.threads = whole(key, v)? as usize,
            "cull" => {
                self.cull = match v {
                    Value::Text(t) => parse_cull(t).map_err(err)?,
                    _ => super::cull(f32_checked(key, v, Ok)?).map_err(err)?,
                }
            }
            "quality" => self.quality = Some(finite(key, v)?),
            "quality_reference" => self.quality_reference = choice(key, v)?,
            _ => return Err(unknown(key)),
        }
        Ok(())
    }
}

/// The error for a keyword no flag has.
pub fn unknown(key: &str) -> CliError {
    CliError::input(format!(
        "unknown keyword '{key}' (the keywords are the flags of `footprint render --help`, with \
         underscores: eye_distance=... for --eye-distance)"
    ))
}
