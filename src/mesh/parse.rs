//! Shared text-reading helpers of the mesh readers: reading a file, iterating over its
//! meaningful lines or whitespace-separated tokens with 1-based line numbers, and parsing
//! numbers into [`MeshError`]s that name the file and the line.

use super::MeshError;
use crate::kernels::math::{Real, Vec3};
use std::path::Path;
use std::str::FromStr;

/// Read the whole file as text, or a [`MeshError`] naming it.
pub(crate) fn read_text(path: &Path) -> Result<String, MeshError> {
    let bytes =
        std::fs::read(path).map_err(|e| MeshError::file(path, format!("cannot read file: {e}")))?;
    String::from_utf8(bytes).map_err(|e| {
        let line = 1 + e.as_bytes()[..e.utf8_error().valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        MeshError::at(path, line, "file is not valid UTF-8 text (binary file?)")
    })
}

/// How many elements to reserve for a count read from a file: the count, capped so that a
/// corrupt header announcing billions of entries cannot exhaust memory before parsing fails.
pub(crate) fn prealloc(declared: usize) -> usize {
    declared.min(1 << 20)
}

/// Check a load scale factor with [`super::validate_scale`], as a [`MeshError`] naming the file.
pub(crate) fn check_scale(path: &Path, scale: Real) -> Result<(), MeshError> {
    super::validate_scale(scale).map_err(|e| MeshError::file(path, e.to_string()))
}

/// The meaningful lines of a text: comments (from `comment` to the end of the line) stripped,
/// surrounding whitespace trimmed, empty lines skipped; each with its 1-based line number.
pub(crate) struct Lines<'a> {
    path: &'a Path,
    inner: std::iter::Enumerate<std::str::Lines<'a>>,
    comment: Option<char>,
    /// 1-based number of the last line of the text (for "unexpected end of file" errors).
    last_line: usize,
}

impl<'a> Lines<'a> {
    /// Lines of `text` (read from `path`), with `comment` starting a comment when given.
    pub(crate) fn new(path: &'a Path, text: &'a str, comment: Option<char>) -> Self {
        Lines {
            path,
            inner: text.lines().enumerate(),
            comment,
            last_line: text.lines().count().max(1),
        }
    }

    /// The next meaningful line, or an error saying that `what` was expected at the end of file.
    pub(crate) fn expect_line(&mut self, what: &str) -> Result<Line<'a>, MeshError> {
        self.next().ok_or_else(|| {
            MeshError::at(
                self.path,
                self.last_line,
                format!("unexpected end of file: expected {what}"),
            )
        })
    }
}

impl<'a> Iterator for Lines<'a> {
    type Item = Line<'a>;
    fn next(&mut self) -> Option<Line<'a>> {
        for (i, raw) in self.inner.by_ref() {
            let body = match self.comment {
                Some(c) => raw.split(c).next().unwrap_or(""),
                None => raw,
            };
            let text = body.trim();
            if !text.is_empty() {
                return Some(Line {
                    path: self.path,
                    number: i + 1,
                    text,
                });
            }
        }
        None
    }
}

/// One meaningful line of a file.
#[derive(Clone, Copy)]
pub(crate) struct Line<'a> {
    path: &'a Path,
    /// 1-based line number.
    pub(crate) number: usize,
    /// The trimmed text without comment.
    pub(crate) text: &'a str,
}

impl<'a> Line<'a> {
    /// An error tied to this line.
    pub(crate) fn error(&self, message: impl Into<String>) -> MeshError {
        MeshError::at(self.path, self.number, message)
    }

    /// The whitespace-separated fields of this line.
    pub(crate) fn fields(&self) -> Fields<'a> {
        Fields {
            line: *self,
            inner: self.text.split_whitespace(),
        }
    }
}

/// The fields of one line, parsed one at a time with errors tied to the line.
pub(crate) struct Fields<'a> {
    line: Line<'a>,
    inner: std::str::SplitWhitespace<'a>,
}

impl<'a> Fields<'a> {
    /// The next field as text, or an error naming the missing `what`.
    pub(crate) fn next_str(&mut self, what: &str) -> Result<&'a str, MeshError> {
        self.inner
            .next()
            .ok_or_else(|| self.line.error(format!("missing {what}")))
    }

    /// The next field parsed as `T`, or an error naming `what`.
    pub(crate) fn next<T: FromStr>(&mut self, what: &str) -> Result<T, MeshError> {
        let s = self.next_str(what)?;
        s.parse::<T>()
            .map_err(|_| self.line.error(format!("invalid {what} `{s}`")))
    }

    /// The next field as a finite real number.
    pub(crate) fn next_real(&mut self, what: &str) -> Result<Real, MeshError> {
        let v: Real = self.next(what)?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.line.error(format!("{what} is not finite")))
        }
    }

    /// The next three fields as a point multiplied by `scale`.
    pub(crate) fn next_point(&mut self, scale: Real) -> Result<Vec3, MeshError> {
        let x = self.next_real("x coordinate")?;
        let y = self.next_real("y coordinate")?;
        let z = self.next_real("z coordinate")?;
        Ok(Vec3::new(x, y, z) * scale)
    }

    /// The remaining fields as text.
    pub(crate) fn rest(self) -> Vec<&'a str> {
        self.inner.collect()
    }
}

/// Whitespace-separated tokens of a text, each with its 1-based line number (for formats such
/// as legacy VTK whose records may span or share lines).
#[derive(Clone)]
pub(crate) struct Tokens<'a> {
    path: &'a Path,
    text: &'a str,
    pos: usize,
    line: usize,
    /// Line of the last token returned (where "unexpected end of file" is reported).
    last_token_line: usize,
}

impl<'a> Tokens<'a> {
    /// Tokens of `text`, starting at byte `pos` which lies on 1-based line `line`.
    pub(crate) fn new(path: &'a Path, text: &'a str, pos: usize, line: usize) -> Self {
        Tokens {
            path,
            text,
            pos,
            line,
            last_token_line: line,
        }
    }

    /// The 1-based line where reading currently stands.
    pub(crate) fn line(&self) -> usize {
        self.line
    }

    /// An error at the current line.
    pub(crate) fn error(&self, message: impl Into<String>) -> MeshError {
        MeshError::at(self.path, self.line, message)
    }

    /// The next token and its line, or `None` at the end of the text.
    pub(crate) fn next_token(&mut self) -> Option<(&'a str, usize)> {
        let bytes = self.text.as_bytes();
        while self.pos < bytes.len() && bytes[self.pos].is_ascii_whitespace() {
            if bytes[self.pos] == b'\n' {
                self.line += 1;
            }
            self.pos += 1;
        }
        if self.pos >= bytes.len() {
            return None;
        }
        let start = self.pos;
        while self.pos < bytes.len() && !bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        self.last_token_line = self.line;
        Some((&self.text[start..self.pos], self.line))
    }

    /// The next token, or an error saying `what` was expected at the end of file.
    pub(crate) fn expect(&mut self, what: &str) -> Result<(&'a str, usize), MeshError> {
        match self.next_token() {
            Some(t) => Ok(t),
            None => Err(MeshError::at(
                self.path,
                self.last_token_line,
                format!("unexpected end of file: expected {what}"),
            )),
        }
    }

    /// The next token parsed as `T`, or an error naming `what` at the token's line.
    pub(crate) fn parse<T: FromStr>(&mut self, what: &str) -> Result<T, MeshError> {
        let (s, line) = self.expect(what)?;
        s.parse::<T>()
            .map_err(|_| MeshError::at(self.path, line, format!("invalid {what} `{s}`")))
    }

    /// The next token as a finite real number.
    pub(crate) fn parse_real(&mut self, what: &str) -> Result<Real, MeshError> {
        let (s, line) = self.expect(what)?;
        match s.parse::<Real>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(_) => Err(MeshError::at(
                self.path,
                line,
                format!("{what} `{s}` is not finite"),
            )),
            Err(_) => Err(MeshError::at(
                self.path,
                line,
                format!("invalid {what} `{s}`"),
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_skip_comments_and_blank_lines() {
        let p = Path::new("x.node");
        let text = "# head\n\n 1 2 3 # tail\n4\n";
        let lines: Vec<_> = Lines::new(p, text, Some('#'))
            .map(|l| (l.number, l.text))
            .collect();
        assert_eq!(lines, vec![(3, "1 2 3"), (4, "4")]);
    }

    #[test]
    fn tokens_track_lines() {
        let p = Path::new("x.vtk");
        let mut t = Tokens::new(p, "a b\n\nc\n d", 0, 1);
        let got: Vec<_> = std::iter::from_fn(|| t.next_token()).collect();
        assert_eq!(got, vec![("a", 1), ("b", 1), ("c", 3), ("d", 4)]);
    }

    #[test]
    fn non_finite_is_rejected() {
        let p = Path::new("x");
        let line = Lines::new(p, "nan 1 2", None).next().unwrap();
        let e = line.fields().next_real("x").unwrap_err();
        assert_eq!(e.line, Some(1));
    }
}
