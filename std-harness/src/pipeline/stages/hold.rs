//! A streamed volume held in memory where the request leaves a choice to a pilot, so that a
//! stream, a file, an array and a generator of the same data get the same plan and the same
//! picture (issue 76).
//!
//! # Why
//! The default plan measures its choices: the slicing and subsampling on a pilot against the
//! continuous integral (`pipeline::quality::pilot::choose_slicing`), `--lod auto`'s level on a
//! pilot of rows against level 0 (`pipeline::quality::level_pilot`), `--quality` both. Each
//! renders candidates whole or marches the reference through the volume, which a stream (read
//! once, three sheets at a time) cannot give: slabs of an oblique view cross every sheet. A
//! stream used to fall back to object slicing and the spacing rule's level, a different picture
//! (31.9 dB at 128² on a 256×256×113 CT head). So a stream whose request leaves such a choice
//! ([`wants_volume`]) is read whole, as the file it is would be loaded, when its pilot would run
//! at all ([`crate::pipeline::stages::visible::pilot_fits`]: the pilot's reference field, 16 bytes
//! a voxel, within the visible lists' budget, at most 16 Mi voxels for samples of up to 2 bytes).
//! Past that a file's default plan renders object slicing unmeasured too, so the stream stays a
//! stream; a file stream still validates `--lod auto`'s level on a pilot of rows as it streams
//! (`pipeline::quality::level_pilot::validated_auto`), so only a pipe too large to hold can
//! differ (read once, it keeps the spacing rule's level).
//!
//! # What it costs
//! The samples, as loading the file costs (`voxels × bytes a sample`), instead of three sheets.
//! Flags that leave nothing to choose keep a stream a stream: a fixed end (`--slicing object`,
//! `--accum fixed` or `--method reference`) with a fixed `--lod N` (0 included), `--refine`, or
//! a perspective view (post-classification and explicit slabs refuse a stream in the plan's
//! flag rules, before anything is held). A held pipe no longer needs `--window` (its range is
//! read as a file's) or a view near the z axis.

use crate::io::formats::raw::RawOptions;
use crate::io::stream::{is_stdin, InMemory};
use crate::io::volume::{byte_len, check_spacing, decode, Volume};
use crate::plan::{Lod, Plan};
use crate::scene::Scene;
use crate::CliError;
use std::sync::Arc;

/// Whether `inputs` with `plan` (the request's plan: a stream's is its file's) leave a choice
/// that a pilot measures on the volume: the default plan's slicing, `--quality`, or `--lod auto`
/// (a perspective view and `--refine` keep level 0 without a pilot).
pub fn wants_volume(inputs: &Scene, plan: &Plan) -> bool {
    let level_pilot = plan.lod == Lod::Auto && inputs.perspective.is_none() && !plan.refines();
    plan.auto_slicing.is_some() || plan.quality.is_some() || level_pilot
}

/// `inputs`' stream (`--stream FILE|-`) read whole, where [`wants_volume`] and the pilot would
/// measure it ([`crate::pipeline::stages::visible::pilot_fits`]); `None` where it stays a stream
/// (or there is none). Called by [`crate::pipeline::entry::prepare`] before anything is loaded. A file is loaded as `footprint render FILE` loads it (same refusals of
/// what cannot stream first); a pipe (standard input, or [`Scene::stdin`]) is read to its
/// `--dims`' last byte and decoded as the raw file would be. The name is the stream's.
pub fn held(inputs: &Scene, plan: &Plan) -> Result<Option<InMemory>, CliError> {
    let Some(stream) = &inputs.stream else {
        return Ok(None);
    };
    if inputs.volume.is_some() || inputs.memory.is_some() || !wants_volume(inputs, plan) {
        return Ok(None);
    }
    let raw = super::load::raw_options(inputs)?;
    if is_stdin(stream) {
        let Some(o) = raw else {
            return Ok(None); // the stream's own refusal says what is missing
        };
        if !fits(o.dims, o.ty.size()) {
            return Ok(None);
        }
        let volume = read_pipe(inputs, &o)?;
        return Ok(Some(in_memory(volume, "standard input".into())));
    }
    let layout = super::load::raw_layout(stream, raw.as_ref())?.layout;
    if !fits(layout.dims, layout.ty.size()) {
        return Ok(None);
    }
    let volume = crate::io::formats::load_array(stream, raw.as_ref(), None)?;
    Ok(Some(in_memory(volume, stream.display().to_string())))
}

fn fits(dims: [usize; 3], sample_bytes: usize) -> bool {
    let voxels = dims[0].saturating_mul(dims[1]).saturating_mul(dims[2]);
    super::visible::pilot_fits(voxels, sample_bytes)
}

fn in_memory(volume: Volume, name: String) -> InMemory {
    let bytes = volume.bytes();
    let size = if bytes < 1 << 20 {
        format!("{:.1} KiB", bytes as f64 / 1024.0)
    } else {
        format!("{:.1} MiB", bytes as f64 / f64::from(1u32 << 20))
    };
    crate::say!(
        "{name}: held in memory ({size}, as the file would be loaded) so that the default \
         plan's pilot measures it; give --lod N with --slicing object to stream it"
    );
    InMemory {
        volume: Arc::new(volume),
        name,
    }
}

/// The pipe's `o.dims` samples, read to the last byte and decoded as `raw::load` decodes a file.
fn read_pipe(inputs: &Scene, o: &RawOptions) -> Result<Volume, CliError> {
    let name = "standard input";
    let need = byte_len(o.dims, o.ty).map_err(|e| CliError::input(format!("{name}: {e}")))?;
    check_spacing(o.spacing).map_err(|e| CliError::input(format!("{name}: {e}")))?;
    let read = |r: &mut dyn std::io::Read| crate::io::read_growing(r, need as u64, name);
    let bytes = match &inputs.stdin {
        Some(pipe) => {
            let mut r = pipe
                .take()
                .ok_or_else(|| CliError::input(format!("{name}: the pipe was read already")))?;
            read(&mut r)
        }
        None => read(&mut std::io::stdin().lock()),
    }
    .map_err(|e| CliError::input(format!("{name}: {e}")))?;
    if bytes.len() < need {
        return Err(CliError::input(format!(
            "{name}: the stream ended after {} of its {need} bytes (the stream is shorter than \
             --dims say)",
            bytes.len()
        )));
    }
    let samples =
        decode(&bytes, o.ty, o.big_endian).map_err(|e| CliError::input(format!("{name}: {e}")))?;
    Ok(Volume::new(o.dims, o.spacing, samples))
}
