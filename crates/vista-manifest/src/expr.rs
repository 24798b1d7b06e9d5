//! Integer expressions of a manifest (SPEC 14 `workgroups`): numbers, param
//! names, `width` and `height`, `+ - * /` (integer division), parentheses
//! and `ceil_div(a, b)`. Parsed and checked once with the manifest; each
//! name must be an integer param or the image size.

use crate::params::{Kind, ParamSet, ParamSpec};

/// A parsed expression.
#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    /// An integer literal.
    Num(i64),
    /// A param, `width` or `height`.
    Name(String),
    /// `a op b`, op one of `+ - * /` (`+ - *` saturate; `/` is Euclidean
    /// division, an error by zero).
    Bin(char, Box<Expr>, Box<Expr>),
    /// `ceil_div(a, b)`: a / b rounded up (b must be positive).
    CeilDiv(Box<Expr>, Box<Expr>),
}

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Num(i64),
    Name(String),
    Op(char),
}

fn lex(text: &str) -> Result<Vec<Tok>, String> {
    let mut out = Vec::new();
    let mut chars = text.chars().peekable();
    while let Some(&c) = chars.peek() {
        if c.is_whitespace() {
            chars.next();
        } else if c.is_ascii_digit() {
            let mut s = String::new();
            while let Some(&d) = chars.peek().filter(|d| d.is_ascii_digit()) {
                s.push(d);
                chars.next();
            }
            out.push(Tok::Num(s.parse().map_err(|_| format!("number {s} is too large"))?));
        } else if c.is_ascii_alphabetic() || c == '_' {
            let mut s = String::new();
            while let Some(&d) = chars.peek().filter(|d| d.is_ascii_alphanumeric() || **d == '_') {
                s.push(d);
                chars.next();
            }
            out.push(Tok::Name(s));
        } else if "+-*/(),".contains(c) {
            out.push(Tok::Op(c));
            chars.next();
        } else {
            return Err(format!("unexpected '{c}'"));
        }
    }
    Ok(out)
}

struct Parser<'a> {
    toks: Vec<Tok>,
    at: usize,
    params: &'a [ParamSpec],
}

impl Parser<'_> {
    fn peek(&self) -> Option<&Tok> {
        self.toks.get(self.at)
    }
    fn eat(&mut self, op: char) -> bool {
        if self.peek() == Some(&Tok::Op(op)) {
            self.at += 1;
            return true;
        }
        false
    }
    fn sum(&mut self) -> Result<Expr, String> {
        let mut e = self.product()?;
        loop {
            let op = if self.eat('+') {
                '+'
            } else if self.eat('-') {
                '-'
            } else {
                return Ok(e);
            };
            e = Expr::Bin(op, Box::new(e), Box::new(self.product()?));
        }
    }
    fn product(&mut self) -> Result<Expr, String> {
        let mut e = self.atom()?;
        loop {
            let op = if self.eat('*') {
                '*'
            } else if self.eat('/') {
                '/'
            } else {
                return Ok(e);
            };
            e = Expr::Bin(op, Box::new(e), Box::new(self.atom()?));
        }
    }
    fn atom(&mut self) -> Result<Expr, String> {
        match self.toks.get(self.at).cloned() {
            Some(Tok::Num(n)) => {
                self.at += 1;
                Ok(Expr::Num(n))
            }
            Some(Tok::Op('(')) => {
                self.at += 1;
                let e = self.sum()?;
                if !self.eat(')') {
                    return Err("expected ')'".into());
                }
                Ok(e)
            }
            Some(Tok::Name(n)) if n == "ceil_div" => {
                self.at += 1;
                if !self.eat('(') {
                    return Err("ceil_div needs (a, b)".into());
                }
                let a = self.sum()?;
                if !self.eat(',') {
                    return Err("ceil_div needs (a, b)".into());
                }
                let b = self.sum()?;
                if !self.eat(')') {
                    return Err("expected ')' after ceil_div's arguments".into());
                }
                Ok(Expr::CeilDiv(Box::new(a), Box::new(b)))
            }
            Some(Tok::Name(n)) => {
                self.at += 1;
                match n.as_str() {
                    "width" => Ok(Expr::Name("width".into())),
                    "height" => Ok(Expr::Name("height".into())),
                    _ => match self.params.iter().find(|p| p.name == n) {
                        Some(p) if matches!(p.kind, Kind::Int { .. }) => Ok(Expr::Name(p.name.clone())),
                        Some(p) => Err(format!("param {n} takes {}, not an integer", p.kind.range_text())),
                        None => Err(format!(
                            "'{n}' is not an integer param, width or height; integer params: {}",
                            names(self.params)
                        )),
                    },
                }
            }
            other => Err(format!("expected a number, a name or '(' but found {}", describe(other.as_ref()))),
        }
    }
}

fn names(params: &[ParamSpec]) -> String {
    let n: Vec<&str> = params.iter().filter(|p| matches!(p.kind, Kind::Int { .. })).map(|p| p.name.as_str()).collect();
    if n.is_empty() { "none".into() } else { n.join(", ") }
}

fn describe(t: Option<&Tok>) -> String {
    match t {
        None => "the end".into(),
        Some(Tok::Num(n)) => n.to_string(),
        Some(Tok::Name(n)) => format!("'{n}'"),
        Some(Tok::Op(c)) => format!("'{c}'"),
    }
}

impl Expr {
    /// Whether the expression reads param (or size) `name`.
    pub fn mentions(&self, name: &str) -> bool {
        match self {
            Expr::Num(_) => false,
            Expr::Name(n) => n == name,
            Expr::Bin(_, a, b) | Expr::CeilDiv(a, b) => a.mentions(name) || b.mentions(name),
        }
    }

    /// Every param (or size) name the expression reads, added to `out`.
    pub fn names<'a>(&'a self, out: &mut Vec<&'a str>) {
        match self {
            Expr::Num(_) => {}
            Expr::Name(n) => out.push(n),
            Expr::Bin(_, a, b) | Expr::CeilDiv(a, b) => {
                a.names(out);
                b.names(out);
            }
        }
    }

    /// One entry of a manifest's `workgroups` or `size` list: a number
    /// >= 1, a param name or an expression (in a string).
    pub fn parse_entry(v: &toml::Value, params: &[ParamSpec]) -> Result<Expr, String> {
        let text = match v {
            toml::Value::Integer(n) if *n >= 1 => n.to_string(),
            toml::Value::String(s) => s.clone(),
            other => {
                return Err(format!(
                    "entry {other} is not valid; expected a number >= 1, a param name or an expression"
                ));
            }
        };
        Expr::parse(&text, params).map_err(|e| format!("entry \"{text}\": {e}"))
    }

    /// [`Expr::parse_entry`] for an offset: any whole number (zero and
    /// negatives too; where it must lie is the caller's to check).
    pub fn parse_offset(v: &toml::Value, params: &[ParamSpec]) -> Result<Expr, String> {
        match v {
            toml::Value::Integer(n) if *n < 0 => Expr::parse(&format!("0 - {}", n.unsigned_abs()), params),
            toml::Value::Integer(n) => Expr::parse(&n.to_string(), params),
            toml::Value::String(s) => Expr::parse(s, params).map_err(|e| format!("entry \"{s}\": {e}")),
            other => Err(format!("{other} is not valid; expected a whole number, a param name or an expression")),
        }
    }

    /// Parses `text` over `params`: each name must be an integer param,
    /// `width` or `height`.
    pub fn parse(text: &str, params: &[ParamSpec]) -> Result<Expr, String> {
        let mut p = Parser { toks: lex(text)?, at: 0, params };
        let e = p.sum()?;
        match p.peek() {
            None => Ok(e),
            Some(t) => Err(format!("unexpected {} after a complete expression", describe(Some(t)))),
        }
    }

    /// The value for these params and image size; a division by zero is an error.
    pub fn eval(&self, p: &ParamSet, width: u32, height: u32) -> Result<i64, String> {
        Ok(match self {
            Expr::Num(n) => *n,
            Expr::Name(n) if n == "width" => width as i64,
            Expr::Name(n) if n == "height" => height as i64,
            Expr::Name(n) => p.int(n),
            Expr::Bin(op, a, b) => {
                let (a, b) = (a.eval(p, width, height)?, b.eval(p, width, height)?);
                match op {
                    '+' => a.saturating_add(b),
                    '-' => a.saturating_sub(b),
                    '*' => a.saturating_mul(b),
                    _ if b == 0 => return Err("division by zero".into()),
                    _ => a.div_euclid(b),
                }
            }
            Expr::CeilDiv(a, b) => {
                let (a, b) = (a.eval(p, width, height)?, b.eval(p, width, height)?);
                if b <= 0 {
                    return Err(format!("ceil_div by {b}"));
                }
                (a + b - 1).div_euclid(b)
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expressions_parse_evaluate_and_name_what_is_wrong() {
        // The built-in fbm's manifest: its integer param `octaves` (8).
        let (_, text) = vista_project::builtin::KERNELS.iter().find(|(f, _)| *f == "fbm.toml").unwrap();
        let k = crate::Kernel::from_manifest("fbm", "<built-in>", text).unwrap();
        let p = k.resolve(None, &[]).unwrap();
        let e = |t: &str| Expr::parse(t, k.params());
        assert_eq!(e("ceil_div(width, 8) * 2 + octaves - (3)").unwrap().eval(&p, 33, 7).unwrap(), 5 * 2 + 8 - 3);
        assert_eq!(e("height / 2").unwrap().eval(&p, 33, 7).unwrap(), 3);
        assert!(e("gain").unwrap_err().contains("not an integer"));
        assert!(e("nope").unwrap_err().contains("integer params: octaves"));
        assert!(e("width +").unwrap_err().contains("found the end"));
        assert!(e("ceil_div(width)").unwrap_err().contains("ceil_div needs"));
        assert!(e("1 / (width - width)").unwrap().eval(&p, 4, 4).unwrap_err().contains("division by zero"));
    }
}
