//! The `--json` summaries, built field by field and written by `serde_json` (pretty-printed,
//! fields in the order they were added). Non-finite numbers are written as `null`; whole numbers
//! (counts, sizes) as integers.

use serde_json::{Map, Value};

/// A JSON object under construction.
#[derive(Clone, Debug, Default)]
pub struct Json {
    fields: Map<String, Value>,
}

/// `v` as a JSON number: an integer when it is a whole number f64 holds exactly, `null` when it
/// is not finite.
fn number(v: f64) -> Value {
    const EXACT: f64 = 9_007_199_254_740_992.0; // 2^53
    if v.is_finite() && v.fract() == 0.0 && v.abs() <= EXACT {
        Value::from(v as i64)
    } else {
        Value::from(v) // serde_json maps NaN and ±inf to null
    }
}

impl Json {
    /// An empty object.
    pub fn object() -> Self {
        Json::default()
    }
    fn push(mut self, key: &str, value: Value) -> Self {
        self.fields.insert(key.to_string(), value);
        self
    }
    /// A string field.
    pub fn str(self, key: &str, v: &str) -> Self {
        self.push(key, Value::from(v))
    }
    /// A number field (null if not finite).
    pub fn num(self, key: &str, v: f64) -> Self {
        self.push(key, number(v))
    }
    /// A `null` field (a value that does not exist, such as the window of data render refuses).
    pub fn null(self, key: &str) -> Self {
        self.push(key, Value::Null)
    }
    /// A boolean field.
    pub fn bool(self, key: &str, v: bool) -> Self {
        self.push(key, Value::from(v))
    }
    /// An array of numbers.
    pub fn arr_f64(self, key: &str, v: &[f64]) -> Self {
        self.push(key, Value::Array(v.iter().map(|&x| number(x)).collect()))
    }
    /// An array of whole numbers.
    pub fn arr_usize(self, key: &str, v: &[usize]) -> Self {
        self.push(
            key,
            Value::Array(v.iter().map(|&x| Value::from(x)).collect()),
        )
    }
    /// An array of objects.
    pub fn arr_obj(self, key: &str, v: Vec<Json>) -> Self {
        self.push(
            key,
            Value::Array(v.into_iter().map(|j| Value::Object(j.fields)).collect()),
        )
    }
    /// A nested object.
    pub fn obj(self, key: &str, v: Json) -> Self {
        self.push(key, Value::Object(v.fields))
    }
    /// The object's text, pretty-printed, with a trailing newline.
    pub fn finish(&self) -> String {
        let mut text = serde_json::to_string_pretty(&self.fields)
            .expect("a map of JSON values with string keys always serialises");
        text.push('\n');
        text
    }
}

#[cfg(test)]
mod tests {
    use super::Json;

    #[test]
    fn fields_keep_their_order_and_types() {
        let j = Json::object()
            .str("z", "a \"quoted\"\nline")
            .num("count", 3.0)
            .num("ratio", 0.25)
            .num("nan", f64::NAN)
            .bool("pass", true)
            .arr_f64("xs", &[1.0, f64::INFINITY])
            .obj("inner", Json::object().num("k", -2.0))
            .finish();
        let v: serde_json::Value = serde_json::from_str(&j).unwrap();
        let keys: Vec<&String> = v.as_object().unwrap().keys().collect();
        assert_eq!(keys, ["z", "count", "ratio", "nan", "pass", "xs", "inner"]);
        assert_eq!(v["z"], "a \"quoted\"\nline");
        assert!(v["count"].is_i64() && v["count"] == 3);
        assert_eq!(v["ratio"], 0.25);
        assert!(v["nan"].is_null() && v["xs"][1].is_null());
        assert_eq!(v["inner"]["k"], -2);
        assert!(j.contains("\"pass\": true") && j.ends_with("}\n"));
    }
}
