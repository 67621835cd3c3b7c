//! SRDF (semantic robot description, as written by MoveIt's setup assistant):
//! its `<disable_collisions>` entries, which take link pairs out of
//! self-collision checking.
//!
//! Only `<disable_collisions link1=... link2=... reason=.../>` is read; every
//! other element (groups, end effectors, virtual joints, ...) is passed over.

use std::path::Path;

use quick_xml::events::{BytesStart, Event};
use quick_xml::Reader;

use super::model::Robot;
use crate::error::{Error, Result};

/// One `<disable_collisions>` entry of an SRDF.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DisabledCollision {
    /// The `link1` attribute.
    pub link1: String,
    /// The `link2` attribute.
    pub link2: String,
    /// The `reason` attribute (`Adjacent`, `Never`, `Default`, ...), if given.
    pub reason: Option<String>,
}

fn srdf_error(name: &str, problem: impl Into<String>) -> Error {
    Error::format(name, "SRDF", problem)
}

/// The 1-based line of byte offset `pos` in `xml`.
fn line_of(xml: &str, pos: u64) -> usize {
    let end = usize::try_from(pos).unwrap_or(usize::MAX).min(xml.len());
    // One more piece than newlines before `end`.
    xml.as_bytes()[..end].split(|&b| b == b'\n').count()
}

/// The attributes `link1`, `link2` and `reason` of a `<disable_collisions>`.
fn disabled_entry(
    reader: &Reader<&[u8]>,
    e: &BytesStart<'_>,
    name: &str,
    line: usize,
) -> Result<DisabledCollision> {
    let (mut link1, mut link2, mut reason) = (None, None, None);
    for attr in e.attributes() {
        let attr = attr.map_err(|err| srdf_error(name, format!("line {line}: {err}")))?;
        let value = attr
            .decode_and_unescape_value(reader.decoder())
            .map_err(|err| srdf_error(name, format!("line {line}: {err}")))?
            .into_owned();
        match attr.key.as_ref() {
            b"link1" => link1 = Some(value),
            b"link2" => link2 = Some(value),
            b"reason" => reason = Some(value),
            _ => {}
        }
    }
    let missing = |which: &str| {
        srdf_error(
            name,
            format!("line {line}: <disable_collisions> has no {which} attribute"),
        )
    };
    Ok(DisabledCollision {
        link1: link1.ok_or_else(|| missing("link1"))?,
        link2: link2.ok_or_else(|| missing("link2"))?,
        reason,
    })
}

/// The `<disable_collisions>` entries of SRDF text, in document order. `name`
/// stands for the file in errors.
///
/// # Errors
/// [`Error::Format`] naming the file (and the line) for malformed XML, a root
/// element other than `<robot>`, or a `<disable_collisions>` without `link1`
/// or `link2`.
pub fn parse_disabled_collisions(xml: &str, name: &str) -> Result<Vec<DisabledCollision>> {
    let mut reader = Reader::from_str(xml);
    let mut out = Vec::new();
    let mut depth = 0usize;
    let mut seen_root = false;
    loop {
        let pos = reader.buffer_position();
        let event = reader.read_event().map_err(|err| {
            let line = line_of(xml, reader.error_position());
            srdf_error(name, format!("malformed XML at line {line}: {err}"))
        })?;
        let (element, opens) = match &event {
            Event::Start(e) => (Some(e), true),
            Event::Empty(e) => (Some(e), false),
            Event::End(_) => {
                depth = depth.saturating_sub(1);
                (None, false)
            }
            Event::Eof => break,
            _ => (None, false),
        };
        let Some(e) = element else { continue };
        let line = line_of(xml, pos);
        if depth == 0 {
            if seen_root || e.name().as_ref() != b"robot" {
                return Err(srdf_error(
                    name,
                    format!(
                        "line {line}: the document must be one <robot> element, found <{}>",
                        String::from_utf8_lossy(e.name().as_ref())
                    ),
                ));
            }
            seen_root = true;
        } else if e.name().as_ref() == b"disable_collisions" {
            out.push(disabled_entry(&reader, e, name, line)?);
        }
        if opens {
            depth += 1;
        }
    }
    if !seen_root {
        return Err(srdf_error(name, "no <robot> element"));
    }
    if depth != 0 {
        return Err(srdf_error(
            name,
            "malformed XML: the document ends inside an element",
        ));
    }
    Ok(out)
}

impl Robot {
    /// Takes the link pairs of the SRDF text's `<disable_collisions>` out of
    /// self-collision checking: each pair leaves
    /// [`Robot::self_collision_pairs`] and joins [`Robot::ignored_pairs`]
    /// (a pair already ignored, or with a link without collision geometry,
    /// changes nothing). `name` stands for the file in errors. Returns the
    /// entries read.
    ///
    /// # Errors
    /// As [`parse_disabled_collisions`]; [`Error::Format`] naming the file and
    /// the link for an entry naming a link the robot does not have. On error
    /// the robot is left unchanged.
    pub fn apply_srdf_str(&mut self, xml: &str, name: &str) -> Result<Vec<DisabledCollision>> {
        let entries = parse_disabled_collisions(xml, name)?;
        let mut pairs = Vec::with_capacity(entries.len());
        for entry in &entries {
            let find = |link: &str| {
                self.link_index(link).ok_or_else(|| {
                    srdf_error(
                        name,
                        format!(
                            "<disable_collisions link1=\"{}\" link2=\"{}\">: robot '{}' has no link named '{link}'",
                            entry.link1, entry.link2, self.name
                        ),
                    )
                })
            };
            pairs.push((find(&entry.link1)?, find(&entry.link2)?));
        }
        for (a, b) in pairs {
            self.disable_pair(a, b);
        }
        Ok(entries)
    }

    /// [`Robot::apply_srdf_str`] of an SRDF file.
    ///
    /// # Errors
    /// [`Error::Io`] if the file cannot be read; as [`Robot::apply_srdf_str`].
    pub fn apply_srdf_file(&mut self, path: &Path) -> Result<Vec<DisabledCollision>> {
        let xml = std::fs::read_to_string(path).map_err(|e| Error::io(path, &e))?;
        self.apply_srdf_str(&xml, &path.display().to_string())
    }

    /// Takes the pair of links named `link_a` and `link_b` out of
    /// self-collision checking, as an SRDF's `<disable_collisions>` does.
    /// Returns whether the pair was checked before.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] naming the link for a link the robot does not
    /// have, or a pair of one link with itself.
    pub fn allow_collision(&mut self, link_a: &str, link_b: &str) -> Result<bool> {
        let find = |link: &str| {
            self.link_index(link).ok_or_else(|| {
                Error::invalid(format!("robot '{}' has no link named '{link}'", self.name))
            })
        };
        let (a, b) = (find(link_a)?, find(link_b)?);
        if a == b {
            return Err(Error::invalid(format!(
                "an allowed collision is a pair of two links, got '{link_a}' twice"
            )));
        }
        let before = self.self_pairs.len();
        self.disable_pair(a, b);
        Ok(self.self_pairs.len() < before)
    }

    /// Moves the pair of links `a` and `b` (indices, either order) from the
    /// checked self-collision pairs to the ignored ones; no change if the pair
    /// is not checked.
    pub(crate) fn disable_pair(&mut self, a: usize, b: usize) {
        let pair = (a.min(b), a.max(b));
        if let Some(k) = self.self_pairs.iter().position(|&p| p == pair) {
            self.self_pairs.remove(k);
            self.ignored_pairs.push(pair);
            self.ignored_pairs.sort_unstable();
        }
    }
}

#[cfg(test)]
mod tests {
    use std::fmt::Write;

    use super::*;

    /// A chain of four boxes along x, each joined to the last by a revolute
    /// joint about z: links a, b, c, d, plus `empty` without geometry.
    fn chain() -> Robot {
        let mut xml = String::from("<robot name=\"chain\">");
        for (i, l) in ["a", "b", "c", "d"].iter().enumerate() {
            write!(
                xml,
                "<link name=\"{l}\"><collision><geometry><box size=\"0.1 0.1 0.1\"/></geometry></collision></link>"
            )
            .unwrap();
            if i > 0 {
                let p = ["a", "b", "c"][i - 1];
                write!(
                    xml,
                    "<joint name=\"j{i}\" type=\"revolute\"><parent link=\"{p}\"/><child link=\"{l}\"/>\
                     <origin xyz=\"0.3 0 0\"/><axis xyz=\"0 0 1\"/>\
                     <limit lower=\"-3\" upper=\"3\" effort=\"1\" velocity=\"1\"/></joint>"
                )
                .unwrap();
            }
        }
        xml.push_str(
            "<link name=\"empty\"/><joint name=\"f\" type=\"fixed\"><parent link=\"d\"/><child link=\"empty\"/></joint></robot>",
        );
        Robot::from_urdf_str(&xml, "chain.urdf", None, &[]).unwrap()
    }

    fn pair_names(r: &Robot, pairs: &[(usize, usize)]) -> Vec<(String, String)> {
        pairs
            .iter()
            .map(|&(a, b)| (r.links()[a].name.clone(), r.links()[b].name.clone()))
            .collect()
    }

    fn names(list: &[(&str, &str)]) -> Vec<(String, String)> {
        list.iter()
            .map(|&(a, b)| (a.to_string(), b.to_string()))
            .collect()
    }

    const SRDF: &str = r#"<?xml version="1.0"?>
<robot name="chain">
  <group name="arm"><chain base_link="a" tip_link="d"/></group>
  <disable_collisions link1="d" link2="b" reason="Never"/>
  <disable_collisions link1="a" link2="b" reason="Adjacent"></disable_collisions>
  <disable_collisions link1="b" link2="empty"/>
</robot>"#;

    #[test]
    fn srdf_parse_reads_entries_in_order() {
        let entries = parse_disabled_collisions(SRDF, "chain.srdf").unwrap();
        let pairs: Vec<_> = entries
            .iter()
            .map(|e| (e.link1.as_str(), e.link2.as_str(), e.reason.as_deref()))
            .collect();
        assert_eq!(
            pairs,
            [
                ("d", "b", Some("Never")),
                ("a", "b", Some("Adjacent")),
                ("b", "empty", None)
            ]
        );
    }

    #[test]
    fn srdf_pairs_removed_from_self_collision() {
        let mut r = chain();
        assert_eq!(
            pair_names(&r, r.self_collision_pairs()),
            names(&[("a", "c"), ("a", "d"), ("b", "d")])
        );
        assert_eq!(
            pair_names(&r, r.ignored_pairs()),
            names(&[("a", "b"), ("b", "c"), ("c", "d")])
        );
        r.apply_srdf_str(SRDF, "chain.srdf").unwrap();
        assert_eq!(
            pair_names(&r, r.self_collision_pairs()),
            names(&[("a", "c"), ("a", "d")])
        );
        assert_eq!(
            pair_names(&r, r.ignored_pairs()),
            names(&[("a", "b"), ("b", "c"), ("b", "d"), ("c", "d")])
        );
        // Folded at j2: d comes back onto b, a pair no longer checked.
        let q = [0.0, 3.0, 0.0];
        let hits: Vec<_> = r
            .self_collisions(&q)
            .unwrap()
            .iter()
            .map(|s| (s.link_a, s.link_b))
            .collect();
        assert!(hits.is_empty(), "{hits:?}");
        let hits: Vec<_> = chain()
            .self_collisions(&q)
            .unwrap()
            .iter()
            .map(|s| (s.link_a, s.link_b))
            .collect();
        assert_eq!(hits, [(1, 3)]);
    }

    #[test]
    fn srdf_unknown_link_is_a_format_error_naming_file_and_link() {
        let mut r = chain();
        let before = r.self_collision_pairs().to_vec();
        let srdf = r#"<robot name="chain"><disable_collisions link1="a" link2="c"/>
            <disable_collisions link1="a" link2="gripper" reason="Never"/></robot>"#;
        let err = r.apply_srdf_str(srdf, "my.srdf").unwrap_err();
        let Error::Format { path, problem, .. } = &err else {
            panic!("{err:?}")
        };
        assert_eq!(path, "my.srdf");
        assert!(problem.contains("'gripper'"), "{problem}");
        // Nothing applied: the robot is as it was.
        assert_eq!(r.self_collision_pairs(), before.as_slice());
    }

    #[test]
    fn srdf_malformed_xml_is_a_format_error() {
        for (xml, needle) in [
            (
                "<robot><disable_collisions link1=\"a\" link2=\"b\"></robot>",
                "line 1",
            ),
            (
                "<robot>\n<disable_collisions link1=\"a\" link2=\"b\"/>",
                "ends inside",
            ),
            ("", "no <robot>"),
            ("<robto/>", "<robto>"),
            ("<robot/><robot/>", "one <robot>"),
            (
                "<robot>\n\n<disable_collisions link1=\"a\"/></robot>",
                "line 3: <disable_collisions> has no link2",
            ),
            (
                "<robot><disable_collisions link1=\"a\" link2=\"b/></robot>",
                "malformed",
            ),
        ] {
            let err = parse_disabled_collisions(xml, "bad.srdf").unwrap_err();
            let Error::Format {
                path,
                format,
                problem,
            } = &err
            else {
                panic!("{xml}: {err:?}")
            };
            assert_eq!((path.as_str(), format.as_str()), ("bad.srdf", "SRDF"));
            assert!(problem.contains(needle), "{xml}: {problem}");
        }
    }

    #[test]
    fn srdf_allow_collision_by_name() {
        let mut r = chain();
        assert!(r.allow_collision("d", "a").unwrap());
        assert!(!r.allow_collision("a", "d").unwrap());
        assert!(!r.allow_collision("a", "b").unwrap()); // adjacent: already ignored
        assert_eq!(
            pair_names(&r, r.self_collision_pairs()),
            names(&[("a", "c"), ("b", "d")])
        );
        assert!(pair_names(&r, r.ignored_pairs()).contains(&("a".into(), "d".into())));
        for (x, y, needle) in [("a", "zz", "'zz'"), ("c", "c", "'c' twice")] {
            let err = r.allow_collision(x, y).unwrap_err();
            let Error::InvalidInput(msg) = &err else {
                panic!("{err:?}")
            };
            assert!(msg.contains(needle), "{msg}");
        }
    }

    #[test]
    fn srdf_file_missing_is_an_io_error() {
        let mut r = chain();
        let err = r
            .apply_srdf_file(Path::new("/nonexistent/robot.srdf"))
            .unwrap_err();
        assert!(matches!(err, Error::Io { .. }), "{err:?}");
    }
}
