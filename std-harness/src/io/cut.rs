//! A brick's samples: read from a file with positioned reads ([`read_box`]) or cut from a whole
//! volume in memory ([`crop`]). The boxes are [`super::brick`]'s.

use super::brick::{BrickPlace, IndexBox};
use super::stream::Layout;
use super::volume::{decode, Samples, Volume};
use crate::CliError;
use std::os::unix::fs::FileExt;

/// The brick `place` of the whole volume whose raw samples `layout` describes, on the grid
/// `spacing` and `directions`, its values through `values`: only its stored box is read
/// ([`read_box`]). Returned with the bytes read.
pub fn read_brick(
    layout: &Layout,
    place: BrickPlace,
    (spacing, directions): ([f32; 3], [[f32; 3]; 3]),
    values: super::volume::ValueMap,
) -> Result<(Volume, u64), CliError> {
    let (samples, bytes) = read_box(layout, place.stored)?;
    let volume = Volume {
        dims: layout.dims,
        spacing,
        directions,
        samples,
        brick: Some(place),
        grid: None,
        values,
    };
    Ok((volume, bytes))
}

/// The samples of box `b` of the raw samples `layout` describes, read with positioned reads (a
/// row of the box at a time, or whole z-slice runs where the box spans full rows), and the bytes
/// read.
pub fn read_box(layout: &Layout, b: IndexBox) -> Result<(Samples, u64), CliError> {
    let err =
        |e: std::io::Error| CliError::input(format!("{}: cannot read: {e}", layout.path.display()));
    let file = std::fs::File::open(&layout.path).map_err(err)?;
    let [nx, ny, _] = layout.dims;
    let size = layout.ty.size();
    let d = b.dims();
    let bytes_len = b.count() * size;
    let mut bytes = super::try_vec::<u8>(bytes_len, "a brick's bytes").map_err(CliError::input)?;
    bytes.resize(bytes_len, 0);
    let at = |i: usize, j: usize, k: usize| layout.offset + (((k * ny + j) * nx + i) * size) as u64;
    let mut pos = 0;
    for k in b.lo[2]..b.hi[2] {
        if d[0] == nx {
            // Full rows: the box's rows of this z-slice are contiguous.
            let n = d[0] * d[1] * size;
            file.read_exact_at(&mut bytes[pos..pos + n], at(0, b.lo[1], k))
                .map_err(err)?;
            pos += n;
        } else {
            for j in b.lo[1]..b.hi[1] {
                let n = d[0] * size;
                file.read_exact_at(&mut bytes[pos..pos + n], at(b.lo[0], j, k))
                    .map_err(err)?;
                pos += n;
            }
        }
    }
    let samples = decode(&bytes, layout.ty, layout.big_endian)
        .map_err(|e| super::volume::at(&layout.path, e))?;
    Ok((samples, bytes_len as u64))
}

/// The brick `place` of `volume` (a whole volume in memory): its stored samples copied out.
pub fn crop(volume: &Volume, place: BrickPlace) -> Result<Volume, CliError> {
    fn cut<T: Copy>(v: &[T], dims: [usize; 3], b: IndexBox) -> Result<Vec<T>, CliError> {
        let mut out = super::try_vec(b.count(), "a brick's samples").map_err(CliError::input)?;
        for k in b.lo[2]..b.hi[2] {
            for j in b.lo[1]..b.hi[1] {
                let row = (k * dims[1] + j) * dims[0];
                out.extend_from_slice(&v[row + b.lo[0]..row + b.hi[0]]);
            }
        }
        Ok(out)
    }
    if volume.brick.is_some() {
        return Err(CliError::input(
            "a brick is cut from a whole volume, not from a brick",
        ));
    }
    let (d, b) = (volume.dims, place.stored);
    let samples = match &volume.samples {
        Samples::U8(v) => Samples::U8(cut(v, d, b)?.into()),
        Samples::I8(v) => Samples::I8(cut(v, d, b)?.into()),
        Samples::U16(v) => Samples::U16(cut(v, d, b)?.into()),
        Samples::I16(v) => Samples::I16(cut(v, d, b)?.into()),
        Samples::U32(v) => Samples::U32(cut(v, d, b)?.into()),
        Samples::I32(v) => Samples::I32(cut(v, d, b)?.into()),
        Samples::F32(v) => Samples::F32(cut(v, d, b)?.into()),
        Samples::F64(v) => Samples::F64(cut(v, d, b)?.into()),
        Samples::Coloured(v) => Samples::Coloured(cut(v, d, b)?.into()),
    };
    Ok(Volume {
        dims: volume.dims,
        spacing: volume.spacing,
        directions: volume.directions,
        samples,
        brick: Some(place),
        // The whole volume's, as `dims` are.
        grid: volume.grid.clone(),
        // The whole volume's: a brick's values are the volume's.
        values: volume.values,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A brick's sheets are the whole volume's inside its stored box and NaN outside, along
    /// every axis; its strided sample is the whole volume's restricted to what it owns.
    #[test]
    fn brick_sheets_match_the_whole() {
        let dims = [7, 5, 6];
        let data: Vec<u16> = (0..dims.iter().product::<usize>() as u16).collect();
        let whole = Volume::new(dims, [1.0; 3], Samples::U16(data.into()));
        let owned = IndexBox {
            lo: [2, 1, 3],
            hi: [5, 4, 6],
        };
        let place = BrickPlace::around(owned, dims);
        assert_eq!(place.stored.lo, [1, 0, 2]);
        assert_eq!(place.stored.hi, [6, 5, 6]);
        let brick = crop(&whole, place).unwrap();
        for axis in 0..3 {
            let (a, b) = footprint::geometry::in_sheet_axes(axis);
            let len = dims[a] * dims[b];
            let (mut w, mut k) = (vec![0.0; len], vec![0.0; len]);
            for s in 0..dims[axis] {
                whole.sheet_into(axis, s, &mut w);
                brick.sheet_into(axis, s, &mut k);
                for v in 0..dims[b] {
                    for u in 0..dims[a] {
                        let mut g = [0; 3];
                        (g[axis], g[a], g[b]) = (s, u, v);
                        let n = u + dims[a] * v;
                        if place.stored.contains(g) {
                            assert_eq!(k[n], w[n], "axis {axis} sheet {s} at {g:?}");
                        } else {
                            assert!(k[n].is_nan(), "axis {axis} sheet {s} at {g:?}");
                        }
                    }
                }
            }
        }
        let all = whole.strided_sample();
        let mine = brick.strided_sample();
        let want: Vec<f32> = all
            .iter()
            .copied()
            .filter(|&x| owned.contains([x as usize % 7, x as usize / 7 % 5, x as usize / 35]))
            .collect();
        assert_eq!(mine, want);
    }

    /// A box read from a raw file with positioned reads equals the box cut from the whole.
    #[test]
    fn read_box_equals_crop() {
        let dims = [6, 4, 5];
        let data: Vec<u16> = (0..120u16).map(|x| x * 3 + 1).collect();
        let dir = tempdir();
        let path = dir.join("v.raw");
        let bytes: Vec<u8> = data.iter().flat_map(|x| x.to_le_bytes()).collect();
        std::fs::write(&path, &bytes).unwrap();
        let layout = Layout {
            path: path.clone(),
            offset: 0,
            dims,
            ty: super::super::volume::SampleType::U16,
            big_endian: false,
            values: super::super::volume::ValueMap::IDENTITY,
        };
        let whole = Volume::new(dims, [1.0; 3], Samples::U16(data.into()));
        for owned in [
            IndexBox {
                lo: [1, 1, 1],
                hi: [4, 3, 4],
            },
            IndexBox {
                lo: [0, 2, 0],
                hi: [6, 4, 5],
            },
        ] {
            let place = BrickPlace::around(owned, dims);
            let (samples, n) = read_box(&layout, place.stored).unwrap();
            assert_eq!(n as usize, place.stored.count() * 2);
            assert_eq!(samples, crop(&whole, place).unwrap().samples);
        }
        std::fs::remove_dir_all(dir).ok();
    }

    fn tempdir() -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("footprint-brick-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }
}
