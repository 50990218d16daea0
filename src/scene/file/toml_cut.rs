//! Cutting a TOML scene file into its `[[objects]]` tables and the rest,
//! so that the tables can be read in batches on every core (see
//! [`super::fast`]). The scanner knows just enough TOML to tell a table
//! header from a line inside a string or an array: strings of every kind,
//! comments, brackets. Whatever it is unsure of gives `None`, and the file
//! is read as one document.

use rayon::prelude::*;
use std::ops::Range;

/// Objects read by one call of a reader: a few hundred, so that the
/// document the `toml` crate builds stays small and the batches spread
/// over cores.
pub(super) const BATCH: usize = 256;

/// A TOML text cut in two: the `[[objects]]` tables (each with its
/// sub-tables), and everything else.
#[derive(Debug, PartialEq)]
pub(super) struct Split {
    /// Everything but the objects, in file order: a TOML document of its
    /// own, since no other table's meaning depends on the objects.
    pub(super) rest: String,
    /// The byte range of each `[[objects]]` table.
    pub(super) objects: Vec<Range<usize>>,
}

/// What the scanner is inside of at a given point of the text.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Inside {
    Code,
    /// `"""…"""`
    MultiLineString,
    /// `'''…'''`
    MultiLineLiteral,
}

/// What a table header starts.
enum Header {
    /// `[[objects]]`: the next object.
    Object,
    /// `[objects.x]` or `[[objects.x]]`: part of the current object.
    ObjectPart,
    /// Any other table.
    Other,
}

/// Bytes of text each thread scans at a time when cutting.
const SCAN_CHUNK: usize = 1 << 22;

/// The sections of `text`, or `None` when it is written in a way the cut
/// might get wrong (then the whole document is read at once).
///
/// The text is scanned in pieces on every core, each piece as if it began
/// outside any string or bracket. That is right when every piece also ends
/// outside them (the first piece starts so, hence by induction each next
/// one); otherwise (a piece boundary inside an array written over several
/// lines, say) the text is scanned again in one piece.
pub(super) fn split(text: &str) -> Option<Split> {
    split_in(text, SCAN_CHUNK)
}

/// [`split`], scanning pieces of about `chunk` bytes.
fn split_in(text: &str, chunk: usize) -> Option<Split> {
    let mut bounds = vec![0];
    while let Some(&last) = bounds.last() {
        if last >= text.len() {
            break;
        }
        let at = last.saturating_add(chunk).min(text.len());
        let next = text.as_bytes()[at..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(text.len(), |i| at + i + 1);
        bounds.push(next);
    }
    let pieces: Option<Vec<Scan>> = bounds
        .par_windows(2)
        .map(|w| scan(text, w[0]..w[1]))
        .collect();
    let scans = match pieces {
        Some(scans) if scans.iter().all(|s| s.closed) => scans,
        _ => vec![scan(text, 0..text.len()).filter(|s| s.closed)?],
    };
    let mut split = Split {
        rest: String::new(),
        objects: Vec::new(),
    };
    // The section being read: where it starts, and whether it is an object.
    let (mut start, mut in_object, mut seen_header) = (0usize, false, false);
    for s in scans {
        // A top-level key `objects` (`objects = […]`, `objects.x = …`).
        if s.objects_key && !seen_header {
            return None;
        }
        for (at, header) in s.headers {
            match header {
                Header::ObjectPart if !in_object => return None,
                Header::ObjectPart => {}
                _ => {
                    close(&mut split, text, start..at, in_object);
                    start = at;
                    in_object = matches!(header, Header::Object);
                }
            }
            seen_header = true;
        }
    }
    close(&mut split, text, start..text.len(), in_object);
    Some(split)
}

/// What a piece of the text holds, scanned as if it began outside any
/// string or bracket.
struct Scan {
    /// The table headers, with where their lines start.
    headers: Vec<(usize, Header)>,
    /// Whether a line before the piece's first header sets a key `objects`.
    objects_key: bool,
    /// Whether the piece ends outside any string or bracket.
    closed: bool,
}

fn scan(text: &str, piece: Range<usize>) -> Option<Scan> {
    let mut out = Scan {
        headers: Vec::new(),
        objects_key: false,
        closed: false,
    };
    let (mut inside, mut depth) = (Inside::Code, 0usize);
    let mut pos = piece.start;
    while pos < piece.end {
        let end = text.as_bytes()[pos..piece.end]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(piece.end, |i| pos + i + 1);
        let line = &text[pos..end];
        if inside == Inside::Code && depth == 0 {
            let t = line.trim_start_matches([' ', '\t']);
            if t.starts_with('[') {
                out.headers.push((pos, header(t)?));
                pos = end;
                continue;
            }
            if out.headers.is_empty() && top_level_objects(t) {
                out.objects_key = true;
            }
        }
        (inside, depth) = scan_line(line, inside, depth)?;
        pos = end;
    }
    out.closed = inside == Inside::Code && depth == 0;
    Some(out)
}

fn close(split: &mut Split, text: &str, section: Range<usize>, object: bool) {
    if object {
        split.objects.push(section);
    } else {
        split.rest.push_str(&text[section]);
    }
}

/// Whether `line`, at the top level, may set `objects`: the key spelled
/// plainly or quoted, or any quoted key with an escape (`"\u006fbjects"`).
fn top_level_objects(line: &str) -> bool {
    let escaped = line
        .strip_prefix('"')
        .and_then(|key| key.split('"').next())
        .is_some_and(|key| key.contains('\\'));
    escaped
        || ["objects", "\"objects\"", "'objects'"].iter().any(|k| {
            line.strip_prefix(k)
                .is_some_and(|after| after.is_empty() || after.starts_with([' ', '\t', '=', '.']))
        })
}

/// What the header at the start of `line` opens; `None` for a quoted name
/// that mentions objects (left to the whole-document reader).
fn header(line: &str) -> Option<Header> {
    let array = line.starts_with("[[");
    let inner = if array { &line[2..] } else { &line[1..] };
    let name = inner.split(']').next().unwrap_or("");
    if name.contains(['"', '\'']) {
        return (!name.contains("objects")).then_some(Header::Other);
    }
    let name = name.trim();
    let first = name.split('.').next().unwrap_or("").trim();
    if first != "objects" {
        return Some(Header::Other);
    }
    match (name == "objects", array) {
        (true, true) => Some(Header::Object),
        // `[objects]`: an error, or a table the cut cannot place.
        (true, false) => None,
        (false, _) => Some(Header::ObjectPart),
    }
}

/// Where `line` leaves the scanner: inside a multi-line string or not, and
/// how deep in brackets. `None` for anything unexpected (a string left open
/// at the end of its line, a closing bracket too many).
fn scan_line(line: &str, mut inside: Inside, mut depth: usize) -> Option<(Inside, usize)> {
    let b = line.as_bytes();
    let at = |i: usize, s: &[u8]| b.get(i..i + s.len()) == Some(s);
    let mut i = 0;
    while i < b.len() {
        match inside {
            Inside::MultiLineString => {
                if b[i] == b'\\' {
                    i += 2;
                    continue;
                }
                if at(i, b"\"\"\"") {
                    i += 3;
                    // Up to two quotes may end the content before the delimiter.
                    while i < b.len() && b[i] == b'"' {
                        i += 1;
                    }
                    inside = Inside::Code;
                    continue;
                }
                i += 1;
            }
            Inside::MultiLineLiteral => {
                if at(i, b"'''") {
                    i += 3;
                    while i < b.len() && b[i] == b'\'' {
                        i += 1;
                    }
                    inside = Inside::Code;
                    continue;
                }
                i += 1;
            }
            Inside::Code => match b[i] {
                b'#' => break,
                b'"' if at(i, b"\"\"\"") => {
                    inside = Inside::MultiLineString;
                    i += 3;
                }
                b'\'' if at(i, b"'''") => {
                    inside = Inside::MultiLineLiteral;
                    i += 3;
                }
                b'"' => {
                    i += 1;
                    loop {
                        match b.get(i)? {
                            b'\\' => i += 2,
                            b'"' => break,
                            b'\n' => return None,
                            _ => i += 1,
                        }
                    }
                    i += 1;
                }
                b'\'' => {
                    i += 1 + line[i + 1..].find(['\'', '\n'])?;
                    if b[i] != b'\'' {
                        return None;
                    }
                    i += 1;
                }
                b'[' | b'{' => {
                    depth += 1;
                    i += 1;
                }
                b']' | b'}' => {
                    depth = depth.checked_sub(1)?;
                    i += 1;
                }
                _ => i += 1,
            },
        }
    }
    Some((inside, depth))
}

/// Runs of consecutive tables among `tables`, up to [`BATCH`] long, as
/// ranges of indices into it.
pub(super) fn batches(tables: &[Range<usize>]) -> Vec<Range<usize>> {
    let mut out: Vec<Range<usize>> = Vec::new();
    for (i, t) in tables.iter().enumerate() {
        match out.last_mut() {
            Some(run) if tables[i - 1].end == t.start && run.len() < BATCH => run.end = i + 1,
            _ => out.push(i..i + 1),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parts(text: &str) -> (String, Vec<&str>) {
        let s = split(text).unwrap();
        (s.rest, s.objects.iter().map(|r| &text[r.clone()]).collect())
    }

    #[test]
    fn objects_are_cut_from_the_rest() {
        let text = "a = 1\n[render]\nwidth = 8\n[[objects]]\ntype = \"x\"\n\
                    [objects.boundary]\nr = 1\n[[ objects ]] # next\nm = \"[[objects]]\"\n\
                    [materials.a]\nt = '''\n[[objects]]\n'''\n";
        let (rest, objects) = parts(text);
        assert_eq!(
            objects,
            [
                "[[objects]]\ntype = \"x\"\n[objects.boundary]\nr = 1\n",
                "[[ objects ]] # next\nm = \"[[objects]]\"\n"
            ]
        );
        assert_eq!(
            rest,
            "a = 1\n[render]\nwidth = 8\n[materials.a]\nt = '''\n[[objects]]\n'''\n"
        );
        // A matrix written over several lines has rows that start with `[`.
        let text = "[[objects]]\nm = [\n [1, 2],\n [3, 4], # ]\n]\n[[objects]]\n";
        assert_eq!(parts(text).1.len(), 2);
    }

    #[test]
    fn pieces_scanned_apart_cut_as_the_whole() {
        let text =
            "a = 1\n[render]\nw = 8\n[[objects]]\nm = \"[[objects]]\"\nc = [\n 1,\n [2],\n]\n\
                    [[objects]]\ns = '''\n[x]\n'''\n[[objects]]\n[objects.b]\nr = 1\n[t]\nq = 2\n";
        let whole = split_in(text, usize::MAX).unwrap();
        assert_eq!(whole.objects.len(), 3);
        for chunk in 0..text.len() + 1 {
            assert_eq!(split_in(text, chunk).as_ref(), Some(&whole), "{chunk}");
        }
        // `objects` set before any header, whichever piece it falls in.
        let text = "a = 1\nb = 2\nobjects = []\n[[objects]]\n";
        for chunk in 0..text.len() + 1 {
            assert!(split_in(text, chunk).is_none(), "{chunk}");
        }
        // After a header, `objects` is a key of that table.
        let text = "[render]\nobjects = 1\n[[objects]]\n";
        for chunk in 0..text.len() + 1 {
            assert_eq!(split_in(text, chunk).unwrap().objects.len(), 1, "{chunk}");
        }
    }

    #[test]
    fn unusual_layouts_are_left_to_the_whole_document() {
        for text in [
            "objects = []\n[[objects]]\n",
            "[objects]\n",
            "[objects.x]\n",
            "[render]\n[objects.x]\n",
            "[\"objects\"]\n",
            "a = \"open\n",
            "a = ]\n",
            "a = \"\"\"\n",
        ] {
            assert!(split(text).is_none(), "{text:?}");
        }
    }

    #[test]
    fn batches_hold_consecutive_objects() {
        let ranges: Vec<Range<usize>> = (0..600).map(|i| i..i + 1).collect();
        let b = batches(&ranges);
        assert_eq!(b, [0..BATCH, BATCH..2 * BATCH, 2 * BATCH..600]);
        assert_eq!(batches(&[0..1, 2..3]), [0..1, 1..2]);
    }
}
