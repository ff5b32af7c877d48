//! A small JSON object writer for the `--json` summaries (flat objects of numbers, strings and
//! arrays; non-finite numbers are written as null).

/// A JSON object under construction.
#[derive(Clone, Debug, Default)]
pub struct Json {
    fields: Vec<String>,
}

fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if (c as u32) < 0x20 => out.push_str(&format!("\\u{:04x}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

fn number(v: f64) -> String {
    if v.is_finite() {
        format!("{v}")
    } else {
        "null".into()
    }
}

impl Json {
    /// An empty object.
    pub fn object() -> Self {
        Json::default()
    }
    fn push(mut self, key: &str, value: String) -> Self {
        self.fields.push(format!("{}: {}", escape(key), value));
        self
    }
    /// A string field.
    pub fn str(self, key: &str, v: &str) -> Self {
        self.push(key, escape(v))
    }
    /// A number field (null if not finite).
    pub fn num(self, key: &str, v: f64) -> Self {
        self.push(key, number(v))
    }
    /// A boolean field.
    pub fn bool(self, key: &str, v: bool) -> Self {
        self.push(key, v.to_string())
    }
    /// An array of numbers.
    pub fn arr_f64(self, key: &str, v: &[f64]) -> Self {
        let items: Vec<String> = v.iter().map(|&x| number(x)).collect();
        self.push(key, format!("[{}]", items.join(", ")))
    }
    /// An array of whole numbers.
    pub fn arr_usize(self, key: &str, v: &[usize]) -> Self {
        let items: Vec<String> = v.iter().map(|x| x.to_string()).collect();
        self.push(key, format!("[{}]", items.join(", ")))
    }
    /// A nested object.
    pub fn obj(self, key: &str, v: Json) -> Self {
        let inner = v.finish();
        self.push(key, inner.trim_end().to_string())
    }
    /// The object's text, with a trailing newline.
    pub fn finish(&self) -> String {
        format!("{{{}}}\n", self.fields.join(", "))
    }
}
