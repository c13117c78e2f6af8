//! pbrt-v4's tokens (words, quoted strings, numbers, brackets, with their line) and a
//! directive's parameters (`"type name" value` or `"type name" [values]`), each marked
//! when the conversion reads it so that what is left can be warned about.
use crate::scene::import::xml::Diagnostic;
use std::path::Path;

#[derive(Clone, Debug, PartialEq)]
pub(super) enum Tok {
    Word(String),
    Str(String),
    Num(f64),
    Open,
    Close,
}

#[derive(Clone, Debug)]
pub(super) struct Token {
    pub(super) tok: Tok,
    pub(super) line: u32,
}

pub(super) fn tokenize(text: &str, file: &Path) -> Result<Vec<Token>, Diagnostic> {
    let mut out = Vec::new();
    let b = text.as_bytes();
    let (mut i, mut line) = (0usize, 1u32);
    let err = |line: u32, m: String| Diagnostic {
        file: file.to_path_buf(),
        line,
        message: m,
    };
    while i < b.len() {
        let c = b[i];
        if c == b'\n' {
            line += 1;
            i += 1;
        } else if c.is_ascii_whitespace() {
            i += 1;
        } else if c == b'#' {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if c == b'[' || c == b']' {
            out.push(Token {
                tok: if c == b'[' { Tok::Open } else { Tok::Close },
                line,
            });
            i += 1;
        } else if c == b'"' {
            let start = i + 1;
            i += 1;
            while i < b.len() && b[i] != b'"' {
                if b[i] == b'\n' {
                    return Err(err(line, "a string runs past the end of its line".into()));
                }
                // pbrt-v4's tokenizer keeps them, but a name or file name holding a
                // carriage return or another control character is a damaged file, and
                // it would break the one-line messages that quote the name.
                if b[i].is_ascii_control() && b[i] != b'\t' {
                    return Err(err(
                        line,
                        format!(
                            "a string holds the control character U+{:04X}; names and file names cannot",
                            b[i]
                        ),
                    ));
                }
                i += 1;
            }
            if i >= b.len() {
                return Err(err(line, "a string is not closed".into()));
            }
            out.push(Token {
                tok: Tok::Str(text[start..i].to_string()),
                line,
            });
            i += 1;
        } else {
            let start = i;
            while i < b.len() && !b[i].is_ascii_whitespace() && !b"[]\"#".contains(&b[i]) {
                i += 1;
            }
            let w = &text[start..i];
            let tok = if w
                .starts_with(|ch: char| ch.is_ascii_digit() || ch == '-' || ch == '+' || ch == '.')
            {
                match w.parse::<f64>() {
                    Ok(v) if v.is_finite() => Tok::Num(v),
                    _ => {
                        return Err(err(
                            line,
                            format!("expected a number, got {:?}", w.escape_debug().to_string()),
                        ))
                    }
                }
            } else {
                Tok::Word(w.to_string())
            };
            out.push(Token { tok, line });
        }
    }
    Ok(out)
}

/// One parameter: `"type name" value` or `"type name" [values]`.
#[derive(Clone, Debug)]
pub(super) struct Param {
    pub(super) ty: String,
    pub(super) name: String,
    pub(super) nums: Vec<f64>,
    pub(super) strs: Vec<String>,
    pub(super) line: u32,
    pub(super) used: std::cell::Cell<bool>,
}

#[derive(Clone, Debug, Default)]
pub(super) struct Params(pub(super) Vec<Param>);

impl Params {
    pub(super) fn get(&self, name: &str) -> Option<&Param> {
        let p = self.0.iter().find(|p| p.name == name)?;
        p.used.set(true);
        Some(p)
    }
    pub(super) fn float(&self, name: &str) -> Option<f64> {
        self.get(name).and_then(|p| p.nums.first().copied())
    }
    pub(super) fn string(&self, name: &str) -> Option<&str> {
        self.get(name)
            .and_then(|p| p.strs.first().map(String::as_str))
    }
}

/// One directive as written: its name and line, its positional arguments (the quoted
/// names it takes, or a transform's numbers) and its parameters.
pub(super) struct Statement {
    pub(super) name: String,
    pub(super) line: u32,
    pub(super) nums: Vec<f64>,
    pub(super) strs: Vec<String>,
    pub(super) params: Params,
}

/// The statements of a file's tokens, parsed one at a time, so that a directive's own
/// error comes before a syntax error after it.
pub(super) struct Statements<'a> {
    toks: Vec<Token>,
    i: usize,
    path: &'a Path,
}

impl<'a> Statements<'a> {
    /// The statements of `text`, the contents of `path` (tokenized whole first).
    pub(super) fn new(text: &str, path: &'a Path) -> Result<Self, Diagnostic> {
        Ok(Statements {
            toks: tokenize(text, path)?,
            i: 0,
            path,
        })
    }

    fn err(&self, line: u32, message: String) -> Diagnostic {
        Diagnostic {
            file: self.path.to_path_buf(),
            line,
            message,
        }
    }

    fn peek(&self) -> Option<&Tok> {
        self.toks.get(self.i).map(|t| &t.tok)
    }

    /// The next statement, or `None` at the end of the file.
    pub(super) fn next_statement(&mut self) -> Option<Result<Statement, Diagnostic>> {
        let token = self.toks.get(self.i)?;
        let line = token.line;
        let Tok::Word(d) = &token.tok else {
            return Some(Err(
                self.err(line, format!("expected a directive, got {:?}", token.tok))
            ));
        };
        let name = d.clone();
        self.i += 1;
        Some(self.arguments(name, line))
    }

    /// Positional arguments: the quoted names a directive takes, or the numbers of a
    /// transform (bare or in brackets); then its parameters.
    fn arguments(&mut self, d: String, line: u32) -> Result<Statement, Diagnostic> {
        let names = match d.as_str() {
            "Texture" => 3,
            "Shape" | "Material" | "MakeNamedMaterial" | "NamedMaterial" | "LightSource"
            | "AreaLightSource" | "Camera" | "Film" | "Sampler" | "Integrator" | "Include"
            | "Import" | "ObjectBegin" | "ObjectInstance" | "PixelFilter" | "Accelerator"
            | "MakeNamedMedium" | "CoordinateSystem" | "CoordSysTransform" | "ColorSpace"
            | "Attribute" | "ActiveTransform" => 1,
            "MediumInterface" => 2,
            _ => 0,
        };
        let mut nums = Vec::new();
        let mut strs = Vec::new();
        for _ in 0..names {
            match self.peek() {
                Some(Tok::Str(x)) => strs.push(x.clone()),
                Some(Tok::Word(x)) if d == "ActiveTransform" => strs.push(x.clone()),
                _ if d == "MediumInterface" && !strs.is_empty() => break,
                _ => return Err(self.err(line, format!("{d}: expected a quoted name after it"))),
            }
            self.i += 1;
        }
        if names == 0 {
            let bracket = self.peek() == Some(&Tok::Open);
            if bracket {
                self.i += 1;
            }
            while let Some(Tok::Num(v)) = self.peek() {
                nums.push(*v);
                self.i += 1;
            }
            if bracket {
                if self.peek() != Some(&Tok::Close) {
                    return Err(self.err(line, format!("{d}: expected numbers and a closing ]")));
                }
                self.i += 1;
            }
        }
        let params = self.params()?;
        Ok(Statement {
            name: d,
            line,
            nums,
            strs,
            params,
        })
    }

    /// Parameters: "type name" value(s), up to the next directive.
    fn params(&mut self) -> Result<Params, Diagnostic> {
        let mut params = Params::default();
        while let Some(Tok::Str(decl)) = self.peek() {
            let mut w = decl.split_whitespace();
            let (Some(ty), Some(name), None) = (w.next(), w.next(), w.next()) else {
                break;
            };
            let mut p = Param {
                ty: ty.to_string(),
                name: name.to_string(),
                nums: Vec::new(),
                strs: Vec::new(),
                line: self.toks[self.i].line,
                used: Default::default(),
            };
            self.i += 1;
            self.values(&mut p)?;
            params.0.push(p);
        }
        Ok(params)
    }

    /// A parameter's value, or its values in brackets.
    fn values(&mut self, p: &mut Param) -> Result<(), Diagnostic> {
        let take = |t: &Tok, p: &mut Param| -> bool {
            match t {
                Tok::Num(v) => p.nums.push(*v),
                Tok::Str(x) => p.strs.push(x.clone()),
                Tok::Word(w) if w == "true" || w == "false" => p.strs.push(w.clone()),
                _ => return false,
            }
            true
        };
        match self.peek() {
            Some(Tok::Open) => {
                self.i += 1;
                while self.i < self.toks.len() && self.toks[self.i].tok != Tok::Close {
                    if !take(&self.toks[self.i].tok, p) {
                        let m = format!("parameter {:?}: expected values inside [ ]", p.name);
                        return Err(self.err(self.toks[self.i].line, m));
                    }
                    self.i += 1;
                }
                if self.i >= self.toks.len() {
                    return Err(self.err(p.line, "a [ is not closed".into()));
                }
                self.i += 1;
            }
            Some(t) if take(t, p) => self.i += 1,
            _ => {
                let m = format!("parameter {:?}: expected a value", p.name);
                return Err(self.err(p.line, m));
            }
        }
        Ok(())
    }
}
