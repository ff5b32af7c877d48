//! `--labels`: a label volume's table (see the core's [`footprint::shade::Labels`]), read from
//! JSON (`{"1": [r, g, b, a], …}`: integer labels, straight colour and opacity each in [0, 1]; the
//! text itself when it starts with `{`, else a file) or from ITK-SNAP's label description file
//! (`IDX R G B A VIS MSH "NAME"` lines, colour 0–255; an invisible label is transparent), and
//! mapped into the renderer's values. Labels absent from the table are transparent.

use crate::io::values::ValueMap;
use crate::CliError;
use footprint::shade::Label;
use std::path::Path;
use std::sync::Arc;

/// The most labels a table may hold.
pub const MAX_LABELS: usize = 65_536;

/// The largest label magnitude: 2²⁴, below which every integer is an exact `f32` (the value the
/// renderer compares samples with).
pub const MAX_LABEL: i64 = 1 << 24;

/// The most bytes a label file may take (1 MiB: 65 536 labels fit many times over).
const MAX_FILE_BYTES: u64 = 1 << 20;

/// A label table as read: integer labels in increasing order, each with its straight RGBA.
#[derive(Clone, Debug, PartialEq)]
pub struct LabelTable {
    /// Where it came from (a path, or `inline` for JSON given as text), for messages.
    pub source: String,
    /// `(label, rgba)`, labels strictly increasing, data units.
    pub entries: Arc<[(i64, [f32; 4])]>,
}

impl LabelTable {
    /// Reads `spec`: JSON text when it starts with `{`, else a file (JSON, or ITK-SNAP's label
    /// description when it does not start with `{`).
    pub fn load(spec: &str) -> Result<LabelTable, CliError> {
        let (source, text) = if spec.trim_start().starts_with('{') {
            ("inline".to_string(), spec.to_string())
        } else {
            let path = Path::new(spec);
            let len = crate::io::regular_file_len(path)?;
            if len > MAX_FILE_BYTES {
                return Err(CliError::input(format!(
                    "--labels {spec}: {len} bytes; a label table is at most {MAX_FILE_BYTES}"
                )));
            }
            let bytes = crate::io::read_file(path)?;
            let text = String::from_utf8(bytes)
                .map_err(|_| CliError::input(format!("--labels {spec}: not text")))?;
            (spec.to_string(), text)
        };
        let refuse = |why: String| CliError::input(format!("--labels {source}: {why}"));
        let mut entries = if text.trim_start().starts_with('{') {
            parse_json(&text).map_err(refuse)?
        } else {
            parse_itksnap(&text).map_err(refuse)?
        };
        entries.sort_by_key(|e| e.0);
        if let Some(w) = entries.windows(2).find(|w| w[0].0 == w[1].0) {
            return Err(refuse(format!("label {} is given twice", w[0].0)));
        }
        if entries.is_empty() {
            return Err(refuse("no label".into()));
        }
        Ok(LabelTable {
            source,
            entries: entries.into(),
        })
    }

    /// The table in the renderer's values (`values` maps the volume's samples): refused where a
    /// label does not map to a value of its own that maps back to it exactly (a wide volume
    /// rebased so far that f32 cannot tell it apart).
    pub fn in_values(&self, values: ValueMap) -> Result<Vec<Label>, CliError> {
        let mut out: Vec<Label> = Vec::with_capacity(self.entries.len());
        for &(label, rgba) in self.entries.iter() {
            let value = values.from_data(label as f64);
            let exact = value.is_finite() && values.to_data(value) == label as f64;
            if !exact || out.last().is_some_and(|l| l.value >= value) {
                return Err(CliError::input(format!(
                    "--labels {}: label {label} has no exact value of its own in this volume's \
                     samples as the renderer reads them (f32{})",
                    self.source,
                    if values.is_identity() {
                        String::new()
                    } else {
                        format!(
                            ", rebased by {} and scaled by {}",
                            values.offset, values.scale
                        )
                    }
                )));
            }
            out.push(Label { value, rgba });
        }
        Ok(out)
    }
}

/// A label key: an integer of magnitude at most [`MAX_LABEL`].
fn key(text: &str) -> Result<i64, String> {
    let t = text.trim();
    match t.parse::<i64>() {
        Ok(k) if k.abs() <= MAX_LABEL => Ok(k),
        Ok(k) => Err(format!(
            "label {k} is beyond ±{MAX_LABEL} (labels are integers the renderer reads exactly)"
        )),
        Err(_) => Err(format!("label '{t}' is not an integer")),
    }
}

/// A colour and opacity: four numbers in [0, 1].
fn rgba(label: i64, v: &[f64]) -> Result<[f32; 4], String> {
    if v.len() != 4 || !v.iter().all(|c| (0.0..=1.0).contains(c)) {
        return Err(format!(
            "label {label}: expected [r, g, b, a], four numbers in [0, 1]"
        ));
    }
    Ok([v[0] as f32, v[1] as f32, v[2] as f32, v[3] as f32])
}

/// Pushes one more label, refusing past [`MAX_LABELS`].
fn push(out: &mut Vec<(i64, [f32; 4])>, entry: (i64, [f32; 4])) -> Result<(), String> {
    if out.len() == MAX_LABELS {
        return Err(format!("more than {MAX_LABELS} labels"));
    }
    out.push(entry);
    Ok(())
}

/// `{"1": [r, g, b, a], …}`; a key given twice is refused (a JSON map would keep the last).
fn parse_json(text: &str) -> Result<Vec<(i64, [f32; 4])>, String> {
    let pairs: Pairs = serde_json::from_str(text)
        .map_err(|e| format!("expected a JSON object of label: [r, g, b, a] ({e})"))?;
    let mut out = Vec::new();
    for (k, v) in pairs.0 {
        let label = key(&k)?;
        push(&mut out, (label, rgba(label, &v)?))?;
    }
    Ok(out)
}

/// A JSON object's entries in order, duplicates kept (so they can be refused).
struct Pairs(Vec<(String, Vec<f64>)>);

impl<'de> serde::Deserialize<'de> for Pairs {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visit;
        impl<'de> serde::de::Visitor<'de> for Visit {
            type Value = Pairs;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an object of label: [r, g, b, a]")
            }
            fn visit_map<M: serde::de::MapAccess<'de>>(self, mut m: M) -> Result<Pairs, M::Error> {
                let mut out = Vec::new();
                while let Some(entry) = m.next_entry::<String, Vec<f64>>()? {
                    if out.len() > MAX_LABELS {
                        return Err(serde::de::Error::custom(format!(
                            "more than {MAX_LABELS} labels"
                        )));
                    }
                    out.push(entry);
                }
                Ok(Pairs(out))
            }
        }
        d.deserialize_map(Visit)
    }
}

/// ITK-SNAP's label description: `IDX R G B A VIS MSH "NAME"` per line (`#` comments), colour
/// 0–255, opacity in [0, 1], VIS 0 hides the label (transparent).
fn parse_itksnap(text: &str) -> Result<Vec<(i64, [f32; 4])>, String> {
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line.split_whitespace().take(7).collect();
        let bad = || {
            format!(
                "line {}: expected 'IDX R G B A VIS MSH \"NAME\"' (ITK-SNAP's label description) \
                 or a JSON object",
                n + 1
            )
        };
        if fields.len() < 7 {
            return Err(bad());
        }
        let label = key(fields[0]).map_err(|e| format!("line {}: {e}", n + 1))?;
        let num = |s: &str| s.parse::<f64>().map_err(|_| bad());
        let (r, g, b, a, vis) = (
            num(fields[1])?,
            num(fields[2])?,
            num(fields[3])?,
            num(fields[4])?,
            num(fields[5])?,
        );
        if ![r, g, b].iter().all(|c| (0.0..=255.0).contains(c)) {
            return Err(format!("line {}: colour channels are 0 to 255", n + 1));
        }
        let a = if vis == 0.0 { 0.0 } else { a };
        let c = rgba(label, &[r / 255.0, g / 255.0, b / 255.0, a])
            .map_err(|e| format!("line {}: {e}", n + 1))?;
        push(&mut out, (label, c)).map_err(|e| format!("line {}: {e}", n + 1))?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_and_itksnap_tables_read_alike() {
        let json = LabelTable::load(r#"{"2": [0, 0, 1, 1], "1": [1, 0, 0, 0.5], "0": [0,0,0,0]}"#)
            .unwrap();
        assert_eq!(
            &*json.entries,
            &[
                (0, [0.0; 4]),
                (1, [1.0, 0.0, 0.0, 0.5]),
                (2, [0.0, 0.0, 1.0, 1.0])
            ]
        );
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("labels.txt");
        std::fs::write(
            &p,
            "# ITK-SNAP Label Description File\n\
             0 0 0 0 0 0 0 \"Clear Label\"\n\
             1 255 0 0 0.5 1 1 \"Liver\"\n\
             2 0 0 255 1 1 1 \"Tumour\"\n\
             3 0 255 0 1 0 1 \"Hidden\"\n",
        )
        .unwrap();
        let snap = LabelTable::load(p.to_str().unwrap()).unwrap();
        assert_eq!(&snap.entries[..3], &json.entries[..]);
        assert_eq!(snap.entries[3], (3, [0.0, 1.0, 0.0, 0.0]));
    }

    #[test]
    fn bad_tables_are_refused_with_a_reason() {
        for (text, why) in [
            (r#"{"1": [1, 0, 0, 1], "1": [0, 1, 0, 1]}"#, "twice"),
            (r#"{"1.5": [1, 0, 0, 1]}"#, "not an integer"),
            (r#"{"99999999": [1, 0, 0, 1]}"#, "beyond"),
            (r#"{"1": [1, 0, 0]}"#, "four numbers"),
            (r#"{"1": [1, 0, 2, 1]}"#, "four numbers"),
            (r#"{"1": "red"}"#, "JSON object"),
            ("{}", "no label"),
            (r#"{"1": [1, 0, 0, 1]"#, "JSON object"),
        ] {
            let e = LabelTable::load(text).unwrap_err().to_string();
            assert!(e.contains(why), "{text}: {e}");
        }
    }

    #[test]
    fn labels_map_exactly_or_are_refused() {
        let t = LabelTable::load(r#"{"5": [1, 0, 0, 1], "7": [0, 1, 0, 1]}"#).unwrap();
        let l = t.in_values(ValueMap::IDENTITY).unwrap();
        assert_eq!((l[0].value, l[1].value), (5.0, 7.0));
        // A map whose scale cannot hold a step of one between labels.
        let coarse = ValueMap {
            offset: 0.0,
            scale: 2f64.powi(-30),
        };
        assert!(t.in_values(coarse).is_ok(), "powers of two scale exactly");
        let rebased = ValueMap {
            offset: 1e12,
            scale: 1.0,
        };
        assert!(t.in_values(rebased).is_err());
    }
}
