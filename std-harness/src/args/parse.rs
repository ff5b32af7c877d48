//! Value parsers for the shared flags: lists, views, sizes, levels of detail, supersampling.

pub use crate::plan::{Lod, Supersample};

/// Parses `a,b,c,…` into exactly `n` finite numbers (f32: one past its range is refused).
pub fn parse_list<const N: usize>(s: &str) -> Result<[f32; N], String> {
    let wide = parse_list_f64::<N>(s)?;
    let mut out = [0.0f32; N];
    for (o, (w, p)) in out.iter_mut().zip(wide.iter().zip(s.split(','))) {
        *o = *w as f32;
        if !o.is_finite() {
            return Err(format!("'{p}' is not finite"));
        }
    }
    Ok(out)
}

/// Parses `a,b,…` into exactly `n` finite f64 numbers (`--window`: wide samples need f64 bounds,
/// as u32 values 4 294 967 290 and 4 294 967 295 are one f32).
pub fn parse_list_f64<const N: usize>(s: &str) -> Result<[f64; N], String> {
    let parts: Vec<&str> = s.split(',').collect();
    if parts.len() != N {
        return Err(format!(
            "expected {N} comma-separated numbers, got {}",
            parts.len()
        ));
    }
    let mut out = [0.0f64; N];
    for (o, p) in out.iter_mut().zip(parts) {
        *o = parse_finite_f64(p)?;
    }
    Ok(out)
}

/// ParaView's view-direction buttons as (azimuth, elevation, roll) of [`parse_view`]'s camera:
/// "+x" looks along +x with +z up, and so on; ±z keep +y up.
pub const VIEW_DIRECTIONS: [(&str, [f32; 3]); 6] = [
    ("+x", [-90.0, 0.0, 90.0]),
    ("-x", [90.0, 0.0, -90.0]),
    ("+y", [0.0, -90.0, 0.0]),
    ("-y", [0.0, 90.0, 180.0]),
    ("+z", [180.0, 0.0, 0.0]),
    ("-z", [0.0, 0.0, 0.0]),
];

/// Parses `--view`: `AZ,EL,ROLL` in degrees, or one of ParaView's directions
/// ([`VIEW_DIRECTIONS`]).
pub fn parse_view(s: &str) -> Result<[f32; 3], String> {
    let t = s.trim().to_ascii_lowercase();
    if let Some((_, a)) = VIEW_DIRECTIONS.iter().find(|(n, _)| *n == t) {
        return Ok(*a);
    }
    parse_list::<3>(s).map_err(|e| format!("{e} (or one of +x, -x, +y, -y, +z, -z)"))
}

/// Parses one finite number (NaN and infinities are refused: `--min-psnr nan` would pass or
/// fail every check the same way, silently).
pub fn parse_finite_f64(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(format!("'{s}' is not finite")),
        Err(_) => Err(format!("'{s}' is not a number")),
    }
}

/// [`parse_finite_f64`] for an f32 flag (also refusing a number past f32's range).
pub fn parse_finite_f32(s: &str) -> Result<f32, String> {
    finite_f32(parse_finite_f64(s)?).map_err(|_| format!("'{s}' is out of range"))
}

/// `v` as an f32 if it is finite there (the typed check [`parse_finite_f32`] makes).
pub fn finite_f32(v: f64) -> Result<f32, String> {
    let f = v as f32;
    if f.is_finite() {
        Ok(f)
    } else {
        Err(format!("{v} is not a finite f32"))
    }
}

/// Parses `X,Y,Z` voxel spacing: three positive finite numbers (world units).
pub fn parse_spacing(s: &str) -> Result<[f32; 3], String> {
    spacing(parse_list::<3>(s)?)
}

/// `v` if every spacing is positive and finite (the typed check [`parse_spacing`] makes).
pub fn spacing(v: [f32; 3]) -> Result<[f32; 3], String> {
    if let Some(bad) = v.iter().find(|x| !(**x > 0.0 && x.is_finite())) {
        return Err(format!(
            "spacing {bad} is not positive (expected X,Y,Z > 0)"
        ));
    }
    Ok(v)
}

/// Parses a positive finite number (a zoom factor).
pub fn parse_positive(s: &str) -> Result<f32, String> {
    let [v] = parse_list::<1>(s)?;
    positive(v)
}

/// `v` if it is positive and finite (the typed check [`parse_positive`] makes).
pub fn positive(v: f32) -> Result<f32, String> {
    if !(v > 0.0 && v.is_finite()) {
        return Err(format!("{v} is not a positive finite number"));
    }
    Ok(v)
}

/// Parses `--perspective`: a field of view in degrees, strictly between 0 and 180.
pub fn parse_fov(s: &str) -> Result<f32, String> {
    let [v] = parse_list::<1>(s)?;
    fov(v)
}

/// `v` if it is a field of view in (0, 180) degrees (the typed check [`parse_fov`] makes).
pub fn fov(v: f32) -> Result<f32, String> {
    if !(v > 0.0 && v < 180.0) {
        return Err(format!("{v}: a field of view is degrees in (0, 180)"));
    }
    Ok(v)
}

/// Parses `--type`: a sample type name (u8, i8, u16, i16, u32, i32, f32, f64, or NRRD's
/// spellings).
pub fn parse_sample_type(s: &str) -> Result<crate::io::volume::SampleType, String> {
    crate::io::volume::SampleType::parse(s)
        .ok_or_else(|| format!("'{s}' is not a sample type (u8, i8, u16, i16, u32, i32, f32, f64)"))
}

/// Parses `--min-radius`: a finite number of pixels, at least the geometry's smallest.
pub fn parse_min_radius(s: &str) -> Result<f32, String> {
    let [v] = parse_list::<1>(s)?;
    min_radius(v)
}

/// `v` if it is a finite radius of at least the geometry's smallest, pixels (the typed check
/// [`parse_min_radius`] makes).
pub fn min_radius(v: f32) -> Result<f32, String> {
    let least = footprint::geometry::MIN_MIN_RADIUS_PX;
    if !(v >= least && v.is_finite()) {
        return Err(format!("{v} px is outside [{least}, ∞) px"));
    }
    Ok(v)
}

/// Parses `auto` or a level 0 … `footprint::lod::MAX_LEVEL`.
pub fn parse_lod(s: &str) -> Result<Lod, String> {
    if s == "auto" {
        return Ok(Lod::Auto);
    }
    match s.parse::<u64>() {
        Ok(n) => level(n).map_err(|_| lod_error(s)),
        _ => Err(lod_error(s)),
    }
}

fn lod_error(s: &str) -> String {
    format!(
        "'{s}': expected auto or a level 0..={} (0 = full resolution)",
        footprint::lod::MAX_LEVEL
    )
}

/// Level `n` if it is one (the typed check [`parse_lod`] makes of a number).
pub fn level(n: u64) -> Result<Lod, String> {
    match u32::try_from(n) {
        Ok(n) if n <= footprint::lod::MAX_LEVEL => Ok(Lod::Level(n)),
        _ => Err(lod_error(&n.to_string())),
    }
}

/// Parses `auto` or a whole number 1 … 8.
pub fn parse_supersample(s: &str) -> Result<Supersample, String> {
    if s == "auto" {
        return Ok(Supersample::Auto);
    }
    match s.parse::<u64>() {
        Ok(k) => factor(k).map_err(|_| factor_error(s)),
        _ => Err(factor_error(s)),
    }
}

fn factor_error(s: &str) -> String {
    format!("'{s}': expected auto or a whole number 1..=8")
}

/// Factor `k` if it is one, 1 … 8 (the typed check [`parse_supersample`] makes of a number).
pub fn factor(k: u64) -> Result<Supersample, String> {
    match k {
        1..=8 => Ok(Supersample::Fixed(k as usize)),
        _ => Err(factor_error(&k.to_string())),
    }
}

/// Parses `WxH` (each 1 … 16384).
pub fn parse_size(s: &str) -> Result<(usize, usize), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("'{s}' is not WxH"))?;
    let parse = |v: &str| -> Result<u64, String> {
        v.parse()
            .map_err(|_| format!("'{v}' is not a whole number in 1..=16384"))
    };
    size([parse(w)?, parse(h)?])
}

/// `(w, h)` pixels if each side is in 1 … 16384 (the typed check [`parse_size`] makes).
pub fn size([w, h]: [u64; 2]) -> Result<(usize, usize), String> {
    let side = |n: u64| {
        if (1..=16384).contains(&n) {
            Ok(n as usize)
        } else {
            Err(format!("image side {n} is outside 1..=16384"))
        }
    };
    Ok((side(w)?, side(h)?))
}

/// Parses `--refine`'s threshold: a finite number ≥ 0.
pub fn parse_threshold(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(v) => threshold(v).map_err(|_| format!("{s:?} is not a finite number ≥ 0")),
        _ => Err(format!("{s:?} is not a finite number ≥ 0")),
    }
}

/// `v` if it is a finite threshold ≥ 0 (the typed check [`parse_threshold`] makes).
pub fn threshold(v: f32) -> Result<f32, String> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(format!("{v} is not a finite number ≥ 0"))
    }
}

/// Parses `--scene-size`: 2 ≤ N ≤ 512.
pub fn parse_scene_size(s: &str) -> Result<usize, String> {
    match s.trim().parse::<u64>() {
        Ok(n) => grid_side(n).map_err(|_| format!("{s:?} is not a grid side in 2..=512")),
        _ => Err(format!("{s:?} is not a grid side in 2..=512")),
    }
}

/// `n` if it is a grid side in 2 … 512 (the typed check [`parse_scene_size`] makes).
pub fn grid_side(n: u64) -> Result<usize, String> {
    if (2..=512).contains(&n) {
        Ok(n as usize)
    } else {
        Err(format!("{n} is not a grid side in 2..=512"))
    }
}

/// The most bricks `--bricks` makes (a million: far past any MPI job's ranks per volume).
pub const MAX_BRICKS: usize = 1 << 20;

/// `--bricks X,Y,Z`: three counts, each at least 1, [`MAX_BRICKS`] at most in all.
pub fn parse_bricks(s: &str) -> Result<[usize; 3], String> {
    let v: Vec<usize> = s
        .split(',')
        .map(|x| x.trim().parse::<usize>().map_err(|e| format!("'{x}': {e}")))
        .collect::<Result<_, _>>()?;
    match v[..] {
        [x, y, z] if x >= 1 && y >= 1 && z >= 1 => Ok([x, y, z]),
        _ => Err(format!(
            "expected X,Y,Z brick counts, each at least 1 (got '{s}')"
        )),
    }
}

/// `--cull EPS|off`: the occlusion threshold ε, or none (`off`).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Cull(pub Option<f32>);

/// `--cull EPS|off`: EPS must lie strictly between 0 and 1.
pub fn parse_cull(s: &str) -> Result<Cull, String> {
    if s.trim() == "off" {
        return Ok(Cull(None));
    }
    let e: f32 = s
        .trim()
        .parse()
        .map_err(|_| format!("'{s}' is neither a number nor 'off'"))?;
    cull(e)
}

/// Culling at `e` if it lies strictly between 0 and 1 (the typed check [`parse_cull`] makes).
pub fn cull(e: f32) -> Result<Cull, String> {
    if e > 0.0 && e < 1.0 {
        Ok(Cull(Some(e)))
    } else {
        Err(format!(
            "'{e}': EPS must lie strictly between 0 and 1 (or be 'off')"
        ))
    }
}

/// `--crop X0:X1,Y0:Y1,Z0:Z1`: three inclusive voxel-index ranges, each FIRST <= LAST (checked
/// against the volume when it is loaded: `Crop::index_box`).
pub fn parse_crop(s: &str) -> Result<crate::scene::Crop, String> {
    let bad = || format!("expected X0:X1,Y0:Y1,Z0:Z1, inclusive voxel indices (got '{s}')");
    let ranges: Vec<[usize; 2]> = s
        .split(',')
        .map(|r| {
            let (lo, hi) = r.split_once(':').ok_or_else(bad)?;
            let n = |x: &str| x.trim().parse::<usize>().map_err(|e| format!("'{x}': {e}"));
            Ok([n(lo)?, n(hi)?])
        })
        .collect::<Result<_, String>>()?;
    let ranges: [[usize; 2]; 3] = ranges.try_into().map_err(|_| bad())?;
    crate::scene::Crop::new(ranges)
}

/// `--clip NX,NY,NZ,D`: keep the world points x with n·x ≤ D (four finite numbers, n not zero).
pub fn parse_clip(s: &str) -> Result<crate::scene::ClipPlane, String> {
    let v: [f64; 4] = parse_list_f64::<4>(s)?;
    crate::scene::ClipPlane::new([v[0], v[1], v[2]], v[3])
}

/// `--depth-phases`: 0 … [`footprint::render::slabs::MAX_DEPTH_PHASES`].
pub fn parse_depth_phases(s: &str) -> Result<usize, String> {
    let max = footprint::render::slabs::MAX_DEPTH_PHASES;
    match s.trim().parse::<u64>() {
        Ok(n) => depth_phases(n)
            .map_err(|_| format!("{s:?} is not a number of depth phases in 0..={max}")),
        _ => Err(format!(
            "{s:?} is not a number of depth phases in 0..={max}"
        )),
    }
}

/// `n` if it is a number of depth phases, 0 … [`footprint::render::slabs::MAX_DEPTH_PHASES`]
/// (the typed check [`parse_depth_phases`] makes).
pub fn depth_phases(n: u64) -> Result<usize, String> {
    let max = footprint::render::slabs::MAX_DEPTH_PHASES;
    match usize::try_from(n) {
        Ok(n) if n <= max => Ok(n),
        _ => Err(format!("{n} is not a number of depth phases in 0..={max}")),
    }
}
