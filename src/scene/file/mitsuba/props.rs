//! A plugin's parameters: its named child elements (`<float name=…>`,
//! `<rgb name=…>`, nested or referenced objects) read by type, each
//! taken once; what no converter took is refused with the names the
//! plugin knows.

use super::spectrum::{self, number, Use};
use super::transform::{self, Mat4};
use super::xml::Element;
use super::{Convert, Failure};
use crate::hint;
use std::cell::RefCell;

/// The tags of parameter values.
const VALUE_TAGS: &[&str] = &[
    "float",
    "integer",
    "boolean",
    "string",
    "rgb",
    "spectrum",
    "point",
    "vector",
    "transform",
];

/// The tags of objects.
pub const OBJECT_TAGS: &[&str] = &[
    "bsdf",
    "texture",
    "emitter",
    "shape",
    "sensor",
    "film",
    "sampler",
    "rfilter",
    "integrator",
    "medium",
    "phase",
    "volume",
];

/// A colour parameter: a colour or a texture element.
pub enum Colour<'e> {
    /// A colour, linear sRGB.
    Rgb([f64; 3]),
    /// A texture.
    Texture(&'e Element),
}

/// The parameters of the plugin `owner`.
pub struct Props<'e> {
    owner: &'e Element,
    /// Named children, each with the element it resolves to (through a
    /// `<ref>`), and whether a converter took it.
    named: Vec<(&'e str, &'e Element, &'e Element)>,
    /// Unnamed object children (resolved).
    unnamed: Vec<&'e Element>,
    taken: RefCell<Vec<bool>>,
}

impl<'e> Props<'e> {
    /// The parameters of `owner`, `<ref>`s resolved through `cx`.
    pub fn of(owner: &'e Element, cx: &Convert<'e>) -> Result<Props<'e>, Failure> {
        let mut named = Vec::new();
        let mut unnamed = Vec::new();
        for c in &owner.children {
            let target = if c.tag == "ref" { cx.resolve(c)? } else { c };
            if c.tag != "ref"
                && !VALUE_TAGS.contains(&c.tag.as_str())
                && !OBJECT_TAGS.contains(&c.tag.as_str())
            {
                let mut known: Vec<&str> = VALUE_TAGS.to_vec();
                known.extend(OBJECT_TAGS);
                known.push("ref");
                return Err(cx.fail_hint(
                    c,
                    format!("<{}> is not an element of a Mitsuba scene here", c.tag),
                    hint::closest(&c.tag, known.iter().copied())
                        .map(|k| format!("did you mean <{k}>?")),
                ));
            }
            match c.attr("name") {
                Some(n) => {
                    if named.iter().any(|(m, _, _)| *m == n) {
                        return Err(cx.fail(c, format!("parameter `{n}` is given twice")));
                    }
                    named.push((n, c, target));
                }
                None if VALUE_TAGS.contains(&c.tag.as_str()) => {
                    return Err(cx.fail(c, format!("<{}> needs a `name` attribute", c.tag)));
                }
                None => unnamed.push(target),
            }
        }
        let n = named.len();
        Ok(Props {
            owner,
            named,
            unnamed,
            taken: RefCell::new(vec![false; n]),
        })
    }

    /// The element of parameter `name` (the written one, and what it
    /// resolves to), marked taken.
    fn get(&self, name: &str) -> Option<(&'e Element, &'e Element)> {
        let i = self.named.iter().position(|(n, _, _)| *n == name)?;
        self.taken.borrow_mut()[i] = true;
        Some((self.named[i].1, self.named[i].2))
    }

    /// The element parameter `name` resolves to, without taking it.
    pub fn peek(&self, name: &str) -> Option<&'e Element> {
        self.named
            .iter()
            .find(|(n, _, _)| *n == name)
            .map(|(_, _, e)| *e)
    }

    /// Marks parameter `name` taken.
    pub fn take(&self, name: &str) {
        let _ = self.get(name);
    }

    /// Whether parameter `name` is given (without taking it).
    pub fn has(&self, name: &str) -> bool {
        self.named.iter().any(|(n, _, _)| *n == name)
    }

    /// The unnamed object children with tag `tag`, and the named ones too
    /// (a nested BSDF may be named).
    pub fn objects(&self, tag: &str) -> Vec<&'e Element> {
        let mut out: Vec<&'e Element> = self
            .unnamed
            .iter()
            .copied()
            .filter(|e| e.tag == tag)
            .collect();
        for (i, (_, _, e)) in self.named.iter().enumerate() {
            if e.tag == tag {
                self.taken.borrow_mut()[i] = true;
                out.push(e);
            }
        }
        out
    }

    /// The value attribute of `e`, required.
    fn value(e: &'e Element, cx: &Convert) -> Result<&'e str, Failure> {
        e.attr("value")
            .ok_or_else(|| cx.fail(e, format!("<{}> needs a `value` attribute", e.tag)))
    }

    fn expect_tag(e: &Element, tags: &[&str], what: &str, cx: &Convert) -> Result<(), Failure> {
        if tags.contains(&e.tag.as_str()) {
            Ok(())
        } else {
            Err(cx.fail(
                e,
                format!(
                    "parameter `{}` must be {what}, got <{}>",
                    e.attr("name").unwrap_or(""),
                    e.tag
                ),
            ))
        }
    }

    /// A number (`<float>` or `<integer>`).
    pub fn float(&self, name: &str, cx: &Convert) -> Result<Option<f64>, Failure> {
        let Some((e, _)) = self.get(name) else {
            return Ok(None);
        };
        Self::expect_tag(e, &["float", "integer"], "a number (<float>)", cx)?;
        number(Self::value(e, cx)?)
            .map(Some)
            .map_err(|m| cx.fail(e, m))
    }

    /// An integer.
    pub fn integer(&self, name: &str, cx: &Convert) -> Result<Option<i64>, Failure> {
        let Some((e, _)) = self.get(name) else {
            return Ok(None);
        };
        Self::expect_tag(e, &["integer"], "an <integer>", cx)?;
        let v = Self::value(e, cx)?;
        v.trim()
            .parse::<i64>()
            .map(Some)
            .map_err(|_| cx.fail(e, format!("expected an integer, got `{v}`")))
    }

    /// A boolean.
    pub fn boolean(&self, name: &str, cx: &Convert) -> Result<Option<bool>, Failure> {
        let Some((e, _)) = self.get(name) else {
            return Ok(None);
        };
        Self::expect_tag(e, &["boolean"], "a <boolean>", cx)?;
        match Self::value(e, cx)?.to_ascii_lowercase().as_str() {
            "true" => Ok(Some(true)),
            "false" => Ok(Some(false)),
            v => Err(cx.fail(e, format!("expected true or false, got `{v}`"))),
        }
    }

    /// A string.
    pub fn string(&self, name: &str, cx: &Convert) -> Result<Option<&'e str>, Failure> {
        let Some((e, _)) = self.get(name) else {
            return Ok(None);
        };
        Self::expect_tag(e, &["string"], "a <string>", cx)?;
        Self::value(e, cx).map(Some)
    }

    /// A string, with the element it was written in.
    pub fn string_at(
        &self,
        name: &str,
        cx: &Convert,
    ) -> Result<Option<(&'e str, &'e Element)>, Failure> {
        let Some((e, _)) = self.get(name) else {
            return Ok(None);
        };
        Self::expect_tag(e, &["string"], "a <string>", cx)?;
        Ok(Some((Self::value(e, cx)?, e)))
    }

    /// A point or vector.
    pub fn point(&self, name: &str, cx: &Convert) -> Result<Option<[f64; 3]>, Failure> {
        let Some((e, _)) = self.get(name) else {
            return Ok(None);
        };
        Self::expect_tag(e, &["point", "vector"], "a <point> or <vector>", cx)?;
        if e.attr("value").is_none()
            && !(e.attr("x").is_some() && e.attr("y").is_some() && e.attr("z").is_some())
        {
            return Err(cx.fail(e, format!("<{}> needs `value` or all of x, y, z", e.tag)));
        }
        transform::triple(e, 0.0, true)
            .map(Some)
            .map_err(|m| cx.fail(e, m))
    }

    /// A transform.
    pub fn transform(&self, name: &str, cx: &Convert) -> Result<Option<Mat4>, Failure> {
        let Some((e, _)) = self.get(name) else {
            return Ok(None);
        };
        Self::expect_tag(e, &["transform"], "a <transform>", cx)?;
        let mut m = transform::IDENTITY;
        for s in &e.children {
            let step = transform::step(s).map_err(|msg| cx.fail(s, msg))?;
            m = transform::mul(&step, &m);
        }
        if !m.iter().flatten().all(|v| v.is_finite()) {
            return Err(cx.fail(e, "the transform is not finite".into()));
        }
        Ok(Some(m))
    }

    /// A colour or a texture for `use_`.
    pub fn colour(
        &self,
        name: &str,
        use_: Use,
        cx: &Convert,
    ) -> Result<Option<Colour<'e>>, Failure> {
        let Some((written, e)) = self.get(name) else {
            return Ok(None);
        };
        match e.tag.as_str() {
            "texture" => Ok(Some(Colour::Texture(e))),
            "float" | "integer" => {
                let v = number(Self::value(e, cx)?).map_err(|m| cx.fail(e, m))?;
                Ok(Some(Colour::Rgb([v; 3])))
            }
            "rgb" => {
                let v = Self::value(e, cx)?;
                let t: Vec<f64> = v
                    .split([',', ' ', '\t', '\n'])
                    .filter(|t| !t.is_empty())
                    .map(number)
                    .collect::<Result<_, _>>()
                    .map_err(|m| cx.fail(e, m))?;
                let rgb = match t[..] {
                    [v] => [v; 3],
                    [r, g, b] => [r, g, b],
                    _ => return Err(cx.fail(e, format!("<rgb> holds {} numbers; expected 3 or 1", t.len()))),
                };
                if use_ == Use::Reflectance && rgb.iter().any(|c| !(0.0..=1.0).contains(c)) {
                    return Err(cx.fail(
                        e,
                        format!("a reflectance must lie within [0, 1], got {v}"),
                    ));
                }
                Ok(Some(Colour::Rgb(rgb)))
            }
            "spectrum" => {
                if e.attr("type").is_some() || e.attr("filename").is_some() {
                    return Err(cx.fail(
                        e,
                        "only spectra given by `value` (one number or wavelength:value pairs) are \
                         read: a blackbody or a spectrum file has no RGB form in Mitsuba's RGB \
                         variants either"
                            .into(),
                    ));
                }
                let rgb = spectrum::parse(Self::value(e, cx)?, use_).map_err(|m| cx.fail(e, m))?;
                Ok(Some(Colour::Rgb(rgb)))
            }
            _ => Err(cx.fail(
                written,
                format!(
                    "parameter `{name}` must be a colour (<rgb>, <spectrum>, <float>) or a <texture>, got <{}>",
                    e.tag
                ),
            )),
        }
    }

    /// A number for a scalar parameter that may also be a texture.
    pub fn scalar(&self, name: &str, cx: &Convert) -> Result<Option<Colour<'e>>, Failure> {
        self.colour(name, Use::Unbounded, cx)
    }

    /// Refuses every parameter no converter took, naming those `known`.
    pub fn finish(&self, known: &[&str], cx: &Convert) -> Result<(), Failure> {
        let taken = self.taken.borrow();
        for (i, (n, e, _)) in self.named.iter().enumerate() {
            if !taken[i] {
                let what = describe(self.owner);
                return Err(cx.fail_hint(
                    e,
                    format!(
                        "{what} has no parameter `{n}`{}",
                        if known.is_empty() {
                            String::new()
                        } else {
                            format!("; its parameters: {}", known.join(", "))
                        }
                    ),
                    hint::closest(n, known.iter().copied()).map(|k| format!("did you mean `{k}`?")),
                ));
            }
        }
        Ok(())
    }
}

/// "<bsdf type=\"diffuse\">".
pub fn describe(e: &Element) -> String {
    match e.attr("type") {
        Some(t) => format!("<{} type=\"{t}\">", e.tag),
        None => format!("<{}>", e.tag),
    }
}
