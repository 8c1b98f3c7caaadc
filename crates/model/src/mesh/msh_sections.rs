//! The sections of an MSH file, walked as gmsh walks them: a line `$Name` opens a section, the
//! next line `$EndName` closes it, and lines between sections that do not start with `$` are
//! skipped. Gmsh reads the sections it knows and skips every other one (`$Comments`, data
//! sections) wherever it appears, before `$MeshFormat` too.
//!
//! Every reader of a Gmsh file's bytes (`mshio`, and the harness's own readers of
//! `$PhysicalNames`, `$Nodes`, element lines and `$PartitionedEntities`) reads them after
//! [`blank_ignored`] has blanked the sections the harness does not read, and from the
//! `$MeshFormat` line [`header`] finds: so a `$Comments` section before the header, or one
//! holding a line `$PhysicalNames`, is skipped by all of them alike.

/// The sections the harness reads (with `mshio` or its own readers); every other is skipped.
pub const READ: [&str; 6] = ["MeshFormat", "PhysicalNames", "Entities", "PartitionedEntities", "Nodes", "Elements"];

/// A section: its name (after `$`), the byte offsets of its opening line and of its body (after
/// that line), and the offset just past its closing line (None: the file has no `$EndName`).
#[derive(Clone, Debug, PartialEq)]
pub struct Section {
    pub name: String,
    pub start: usize,
    pub body: usize,
    pub end: Option<usize>,
}

/// A section name as a message shows it: control characters escaped (a file's bytes must not
/// drive the terminal: an escape sequence could clear it), at most 60 characters.
fn shown(name: &str) -> String {
    let mut out = String::new();
    for (i, c) in name.chars().enumerate() {
        if i == 60 {
            out.push_str("...");
            break;
        }
        if c.is_control() { out.extend(c.escape_default()) } else { out.push(c) }
    }
    out
}

/// The end of the line starting at `pos` (the offset of its `\n`, or the file's end).
fn line_end(bytes: &[u8], pos: usize) -> usize {
    bytes[pos..].iter().position(|&b| b == b'\n').map_or(bytes.len(), |i| pos + i)
}

/// The offset just past the first line from `from` on that reads `$End{name}` (blanks around it
/// allowed), if any.
fn closing(bytes: &[u8], from: usize, name: &str) -> Option<usize> {
    let end = format!("$End{name}");
    let mut pos = from;
    while pos < bytes.len() {
        let eol = line_end(bytes, pos);
        if bytes[pos..eol].trim_ascii() == end.as_bytes() {
            return Some((eol + 1).min(bytes.len()));
        }
        pos = eol + 1;
    }
    None
}

/// The file's sections in order, up to the first one that is not closed (included, with `end`
/// None). Inside a section nothing is read but its closing line (binary data included).
pub fn walk(bytes: &[u8]) -> Vec<Section> {
    let mut sections = Vec::new();
    let mut pos = 0;
    while pos < bytes.len() {
        let eol = line_end(bytes, pos);
        let line = bytes[pos..eol].trim_ascii();
        let Some(name) = line.strip_prefix(b"$") else {
            // not a section's opening line: skipped (gmsh skips it too; mshio names it if it
            // lies after the header)
            pos = eol + 1;
            continue;
        };
        let name = String::from_utf8_lossy(name).into_owned();
        let body = (eol + 1).min(bytes.len());
        let end = closing(bytes, body, &name);
        sections.push(Section { name, start: pos, body, end });
        match end {
            Some(e) => pos = e,
            None => break,
        }
    }
    sections
}

/// The offset of the `$MeshFormat` line, the first section of its own (not a line inside a
/// section skipped before it).
pub fn header(bytes: &[u8]) -> Option<usize> {
    walk(bytes).into_iter().find(|s| s.name == "MeshFormat").map(|s| s.start)
}

/// The UTF-8 byte-order mark some editors write at a text file's start.
const BYTE_ORDER_MARK: &[u8] = b"\xEF\xBB\xBF";

/// `bytes` with every section the harness does not read ([`READ`]) blanked, and every line
/// between sections the walk skips (one that does not start with `$`), each of their bytes but
/// the line ends made a space (offsets and line numbers stay where they are): every reader
/// skips what gmsh skips. Refused, with the 1-based line and why: a skipped section that is
/// never closed, a file that starts with a byte-order mark (gmsh refuses it too; its first
/// line is then not `$MeshFormat`).
pub fn blank_ignored(mut bytes: Vec<u8>) -> Result<Vec<u8>, (usize, String)> {
    if bytes.starts_with(BYTE_ORDER_MARK) {
        return Err((
            1,
            "the file starts with a byte-order mark (the bytes EF BB BF, before its first line): save it without one (gmsh refuses it too)"
                .to_string(),
        ));
    }
    let mut kept = 0;
    let sections = walk(&bytes);
    for (k, s) in sections.iter().enumerate() {
        blank(&mut bytes[kept..s.start]);
        if READ.contains(&s.name.as_str()) {
            kept = s.end.unwrap_or(bytes.len());
            continue;
        }
        let Some(end) = s.end else {
            let line_of = |offset: usize| 1 + bytes[..offset].iter().filter(|&&b| b == b'\n').count();
            let line = line_of(s.start);
            // a `$EndName` line outside its section: the section ended before, at a line the
            // walk took for its end (binary data can hold those bytes)
            let closed = s.name.strip_prefix("End").and_then(|n| sections[..k].iter().rev().find(|o| o.name == n));
            return Err(match closed {
                Some(o) => (
                    line,
                    format!(
                        "the line ${} closes no section: ${} (line {}) ended at line {}, the first line reading ${} after it{}",
                        shown(&s.name),
                        shown(&o.name),
                        line_of(o.start),
                        o.end.map_or(line, |e| line_of(e - 1)),
                        shown(&s.name),
                        if o.name == "Nodes" || o.name == "Elements" {
                            " (in a binary file, its data may hold those bytes: write the file in ASCII)"
                        } else {
                            ""
                        }
                    ),
                ),
                None => {
                    let name = shown(&s.name);
                    (line, format!("the section ${name} has no line $End{name}: every section must be closed"))
                }
            });
        };
        blank(&mut bytes[s.start..end]);
        kept = end;
    }
    blank(&mut bytes[kept..]);
    Ok(bytes)
}

/// Every byte but the line ends made a space.
fn blank(bytes: &mut [u8]) {
    bytes.iter_mut().filter(|b| **b != b'\n').for_each(|b| *b = b' ');
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Comments before the header, between sections and holding a `$` line are blanked, line
    /// by line; the sections read are kept byte for byte.
    #[test]
    fn comments_anywhere_are_blanked() {
        let file = "$Comments\nhi\n$PhysicalNames\n$EndComments\n$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Foo\nx\n$EndFoo\n$Nodes\n0 0 0 0\n$EndNodes\n";
        let out = String::from_utf8(blank_ignored(file.as_bytes().to_vec()).unwrap()).unwrap();
        assert_eq!(out.lines().count(), file.lines().count());
        assert!(!out.contains("PhysicalNames") && !out.contains("Comments") && !out.contains("Foo"), "{out}");
        assert_eq!(header(out.as_bytes()), file.find("$MeshFormat"));
        assert!(out.ends_with("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n    \n \n       \n$Nodes\n0 0 0 0\n$EndNodes\n"), "{out:?}");
        let unclosed = blank_ignored(b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Comments\nno end\n".to_vec());
        assert_eq!(unclosed, Err((4, "the section $Comments has no line $EndComments: every section must be closed".into())));
    }

    /// A section name is shown with its control characters escaped and cut to 60 characters
    /// (an escape sequence in a name would otherwise clear the terminal of whoever reads the error).
    #[test]
    fn a_section_name_in_a_message_cannot_drive_the_terminal() {
        let long = "x".repeat(100);
        let file = format!("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Bad\x1b[2J\x1b[31m\n1\n$X{long}\n");
        let (_, message) = blank_ignored(file.into_bytes()).unwrap_err();
        assert!(!message.contains('\x1b') && message.contains("\\u{1b}[2J"), "{message:?}");
        let (_, message) = blank_ignored(format!("$X{long}\n").into_bytes()).unwrap_err();
        assert!(message.contains(&format!("$X{}...", "x".repeat(59))) && !message.contains(&long), "{message:?}");
    }

    /// Lines between sections that do not start with `$` are blanked (gmsh skips them), before
    /// the header, between sections and after the last; a byte-order mark is named.
    #[test]
    fn stray_lines_are_blanked_and_a_byte_order_mark_named() {
        let file = "junk\n$MeshFormat\n4.1 0 8\n$EndMeshFormat\nstray 1\n$Nodes\n0 0 0 0\n$EndNodes\nafter\n  last";
        let out = String::from_utf8(blank_ignored(file.as_bytes().to_vec()).unwrap()).unwrap();
        assert_eq!(out, "    \n$MeshFormat\n4.1 0 8\n$EndMeshFormat\n       \n$Nodes\n0 0 0 0\n$EndNodes\n     \n      ");
        let bom = blank_ignored(b"\xEF\xBB\xBF$MeshFormat\n4.1 0 8\n$EndMeshFormat\n".to_vec()).unwrap_err();
        assert_eq!(bom.0, 1);
        assert!(bom.1.contains("starts with a byte-order mark") && bom.1.contains("save it without one"), "{}", bom.1);
    }

    /// A `$EndNodes` line after the section's end (binary data holding those bytes) is named as
    /// such, with where the walk ended the section.
    #[test]
    fn an_end_line_outside_its_section_is_named() {
        let file = b"$MeshFormat\n4.1 1 8\n$EndMeshFormat\n$Nodes\nab\n$EndNodes\ncd\n$EndNodes\n$Elements\n$EndElements\n";
        let (line, why) = blank_ignored(file.to_vec()).unwrap_err();
        assert_eq!(line, 8);
        assert!(why.starts_with("the line $EndNodes closes no section: $Nodes (line 4) ended at line 6,"), "{why}");
        assert!(why.contains("binary"), "{why}");
    }
}
