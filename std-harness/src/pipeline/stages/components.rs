//! A volume of 2 to 4 components per voxel (MetaImage `ElementNumberOfChannels`, VTK XML
//! `NumberOfComponents`), classified voxel by voxel before reconstruction into a palette: each
//! voxel's straight colour and opacity, from its components, become one entry of a label table
//! (`footprint::shade::Labels`), and the volume the index of its entry. Everything after (every
//! pre-classified path, the continuous model) sees a label volume (docs/components.md).
//!
//! - **RGBA** (4 components, no `--tf`): the components are the colour and the opacity, integer
//!   samples divided by their type's largest value, floats taken as they are (clamped to [0, 1]).
//! - **Independent** (one `--tf` per component, or one for all): each component through its own
//!   transfer function (over its own window: `--window`, else its default one), the materials
//!   mixed as co-located media: extinctions add, σ = Σ σ_c with σ_c = −ln(1 − α_c), so
//!   α = 1 − Π (1 − α_c), and the emitted colour is the extinction-weighted mean Σ σ_c c_c / σ.

use crate::io::volume::{Samples, Volume};
use crate::scene::Scene;
use crate::tf::labels::{LabelTable, MAX_LABEL};
use crate::CliError;
use std::collections::HashMap;
use std::sync::Arc;

/// How the components become a colour.
enum Mode {
    Rgba,
    Independent(Vec<(Vec<[f32; 4]>, [f32; 2])>),
}

/// `parts` (the components of `name`, each a volume) as a palette-index volume and its table.
pub fn classify(
    parts: &[Volume],
    args: &Scene,
    name: &str,
) -> Result<(Volume, LabelTable), CliError> {
    let refuse =
        |why: String| CliError::input(format!("{name}: {} components: {why}", parts.len()));
    if args.labels.is_some() {
        return Err(refuse(
            "--labels colours a label volume of one component: drop it".into(),
        ));
    }
    let mode = match args.tfs.len() {
        0 if parts.len() == 4 => Mode::Rgba,
        n if n <= 1 || n == parts.len() => {
            let mut each = Vec::with_capacity(parts.len());
            for (c, v) in parts.iter().enumerate() {
                let spec = match args.tfs.get(c).or(args.tfs.first()) {
                    Some(t) => t.clone(),
                    None => args.tf_name(),
                };
                let lut = crate::tf::lut(&crate::tf::load(&spec)?);
                let window = match args.window {
                    Some(w) => super::window::check_given(w, v.values)?,
                    None => super::window::default_window(
                        &format!("{name}: {} components: component {c}", parts.len()),
                        Some(v.range()),
                        None,
                        Some(&v.strided_sample()),
                    )?,
                };
                each.push((lut, window));
            }
            Mode::Independent(each)
        }
        n => {
            return Err(refuse(format!(
                "{n} --tf given: give one per component, one for all, or none for 4 (RGBA)"
            )))
        }
    };
    let n = parts[0].len();
    let mut palette: HashMap<[u32; 4], u32> = HashMap::new();
    let mut entries: Vec<(i64, [f32; 4])> = vec![(0, [0.0; 4])];
    let mut index = Vec::with_capacity(n);
    for i in 0..n {
        let rgba = match &mode {
            Mode::Rgba => rgba_of(parts, i),
            Mode::Independent(each) => mixed(parts, each, i),
        };
        if !(rgba[3] > 0.0) {
            index.push(0.0f32);
            continue;
        }
        let next = entries.len() as u32;
        let k = *palette.entry(rgba.map(f32::to_bits)).or_insert(next);
        if k == next {
            if i64::from(next) > MAX_LABEL {
                return Err(refuse(format!(
                    "more than {MAX_LABEL} distinct colours: the palette's indices must be exact \
                     f32s"
                )));
            }
            entries.push((i64::from(next), rgba));
        }
        index.push(k as f32);
    }
    let mut volume = Volume::new(parts[0].dims, parts[0].spacing, Samples::F32(index.into()));
    volume.directions = parts[0].directions;
    let table = LabelTable {
        source: format!("{name} (classified components)"),
        entries: Arc::from(entries),
    };
    Ok((volume, table))
}

/// A component's sample `i` scaled to [0, 1]: integers divided by their type's largest value.
fn unit(v: &Volume, i: usize) -> f32 {
    let top = match v.samples {
        Samples::U8(_) => f64::from(u8::MAX),
        Samples::I8(_) => f64::from(i8::MAX),
        Samples::U16(_) => f64::from(u16::MAX),
        Samples::I16(_) => f64::from(i16::MAX),
        Samples::U32(_) => f64::from(u32::MAX),
        Samples::I32(_) => f64::from(i32::MAX),
        _ => 1.0,
    };
    let x = (v.values.to_data(v.value(i)) / top) as f32;
    if x.is_nan() {
        0.0
    } else {
        x.clamp(0.0, 1.0)
    }
}

/// Voxel `i` of four components as straight RGBA.
fn rgba_of(parts: &[Volume], i: usize) -> [f32; 4] {
    [0, 1, 2, 3].map(|c| unit(&parts[c], i))
}

/// Voxel `i`'s components, each through its transfer function, mixed (see the module docs).
fn mixed(parts: &[Volume], each: &[(Vec<[f32; 4]>, [f32; 2])], i: usize) -> [f32; 4] {
    let (mut sigma, mut colour) = (0.0f64, [0.0f64; 3]);
    for (v, (lut, window)) in parts.iter().zip(each) {
        let tf = footprint::shade::TransferFunction {
            lut,
            lo: window[0],
            hi: window[1],
        };
        let [r, g, b, a] = tf.lookup(v.value(i));
        let a = f64::from(a.clamp(0.0, footprint::lod::MAX_ALPHA));
        if a > 0.0 {
            let s = -(1.0 - a).ln();
            sigma += s;
            for (acc, c) in colour.iter_mut().zip([r, g, b]) {
                *acc += s * f64::from(c);
            }
        }
    }
    if !(sigma > 0.0) {
        return [0.0; 4];
    }
    let c = colour.map(|x| (x / sigma).clamp(0.0, 1.0) as f32);
    [c[0], c[1], c[2], (1.0 - (-sigma).exp()) as f32]
}

/// What a classified volume cannot be drawn with (the plan was resolved before the file said it
/// has several components): what `--labels` refuses, for the same reasons.
pub fn rules(plan: &crate::plan::Plan, args: &Scene, name: &str) -> Result<(), CliError> {
    use crate::plan::{End, Lod};
    let why = if !matches!(args.shading, crate::scene::ShadingSpec::Emission) {
        Some("--shading: components are classified into colours before reconstruction; they render unlit")
    } else if matches!(plan.end, End::Post { .. }) {
        Some("--classification post and --blend reconstruct one value between voxels; components are classified before reconstruction")
    } else if matches!(plan.lod, Lod::Level(1..)) {
        Some("--lod: a coarser level averages values, and an average of palette indices names no colour (give --lod 0 or auto)")
    } else if plan.quality.is_some() {
        Some("--quality chooses among levels of detail: give --slab or --slicing instead")
    } else {
        None
    };
    match why {
        Some(why) => Err(CliError::input(format!(
            "{name}: a multi-component volume with {why}"
        ))),
        None => Ok(()),
    }
}

/// The label table a render classifies by, in the renderer's `values`: a multi-component
/// volume's palette (`classified`, checked against the plan), or `--labels`; `None` for a
/// volume of measurements (which takes one `--tf`).
pub fn labels_of(
    classified: Option<&LabelTable>,
    args: &Scene,
    plan: &crate::plan::Plan,
    name: &str,
    values: crate::io::values::ValueMap,
) -> Result<Option<Arc<[footprint::shade::Label]>>, CliError> {
    if classified.is_some() {
        rules(plan, args, name)?;
    }
    match classified.or(args.labels.as_ref()) {
        Some(t) => Ok(Some(t.in_values(values)?.into())),
        None if args.tfs.len() > 1 => Err(CliError::input(format!(
            "{name}: {} --tf given: one per component of a multi-component volume; this one has \
             one component",
            args.tfs.len()
        ))),
        None => Ok(None),
    }
}
