//! A directive's parameter list: `"type name" value` or `"type name"
//! [values]`, each taken once by the directive's reader, by type; what
//! is left over is refused with the names the directive knows.

use super::lex::At;
use std::cell::Cell;

/// A parameter's values.
#[derive(Clone, Debug, PartialEq)]
pub enum Values {
    /// Numbers.
    Nums(Vec<f64>),
    /// Strings.
    Strs(Vec<String>),
    /// Booleans.
    Bools(Vec<bool>),
}

/// One parameter as written.
#[derive(Clone, Debug)]
pub struct Param {
    /// Its type as written ("float", "rgb", "point3", …).
    pub ty: String,
    /// Its name.
    pub name: String,
    /// Its values.
    pub values: Values,
    /// Where its `"type name"` was written.
    pub at: At,
    used: Cell<bool>,
}

impl Param {
    /// A parameter read from the file.
    pub fn new(ty: String, name: String, values: Values, at: At) -> Param {
        Param {
            ty,
            name,
            values,
            at,
            used: Cell::new(false),
        }
    }
}

/// A colour or spectrum parameter, as written.
#[derive(Clone, Debug, PartialEq)]
pub enum Spectral {
    /// `"rgb"`: linear sRGB.
    Rgb([f64; 3]),
    /// `"spectrum"` as wavelength–value pairs.
    Samples(Vec<f64>),
    /// `"spectrum"` named (`metal-Au-eta`, `glass-BK7`, …) or a file.
    Named(String),
    /// `"blackbody"`: a temperature in kelvin.
    Blackbody(f64),
    /// `"texture"`: a texture's name.
    Texture(String),
    /// A plain `"float"`: the same on every channel.
    Grey(f64),
}

/// A value and where it was written, if given.
pub type Located<T> = Option<(T, At)>;

/// What is wrong with a parameter: where, what, and a hint.
pub type Problem = (At, String, Option<String>);

/// A directive's parameters.
#[derive(Debug, Default)]
pub struct Params {
    /// In the order written.
    pub list: Vec<Param>,
}

/// Types that name the same thing.
fn same_type(written: &str, wanted: &str) -> bool {
    fn canon(t: &str) -> &str {
        match t {
            "point" => "point3",
            "normal" => "normal3",
            "vector" => "vector3",
            "color" => "rgb",
            other => other,
        }
    }
    canon(written) == canon(wanted)
}

impl Params {
    /// The parameter called `name`, marked as taken.
    pub fn get(&self, name: &str) -> Option<&Param> {
        let p = self.list.iter().rev().find(|p| p.name == name)?;
        p.used.set(true);
        Some(p)
    }

    /// Whether a parameter called `name` was given (not marking it).
    pub fn has(&self, name: &str) -> bool {
        self.list.iter().any(|p| p.name == name)
    }

    fn typed(&self, name: &str, types: &[&str]) -> Result<Option<&Param>, Problem> {
        let Some(p) = self.get(name) else {
            return Ok(None);
        };
        if types.iter().any(|t| same_type(&p.ty, t)) {
            Ok(Some(p))
        } else {
            Err((
                p.at,
                format!(
                    "`{name}` is given as \"{}\"; expected {}",
                    p.ty,
                    types
                        .iter()
                        .map(|t| format!("\"{t} {name}\""))
                        .collect::<Vec<_>>()
                        .join(" or ")
                ),
                None,
            ))
        }
    }

    /// The numbers of `name`, of one of `types`.
    pub fn nums(&self, name: &str, types: &[&str]) -> Result<Option<(&[f64], At)>, Problem> {
        let Some(p) = self.typed(name, types)? else {
            return Ok(None);
        };
        match &p.values {
            Values::Nums(v) => Ok(Some((v, p.at))),
            _ => Err((p.at, format!("`{name}` must hold numbers"), None)),
        }
    }

    /// `name`'s numbers in groups of `N` (points, normals, pairs).
    pub fn tuples<const N: usize>(
        &self,
        name: &str,
        types: &[&str],
    ) -> Result<Located<Vec<[f64; N]>>, Problem> {
        let Some((v, at)) = self.nums(name, types)? else {
            return Ok(None);
        };
        if v.len() % N != 0 {
            return Err((
                at,
                format!("`{name}` holds {} numbers, not a multiple of {N}", v.len()),
                None,
            ));
        }
        let tuples = v
            .chunks_exact(N)
            .map(|c| std::array::from_fn(|i| c[i]))
            .collect();
        Ok(Some((tuples, at)))
    }

    /// One number of type "float".
    pub fn float(&self, name: &str) -> Result<Option<f64>, Problem> {
        self.one_num(name, "float")
    }

    fn one_num(&self, name: &str, ty: &str) -> Result<Option<f64>, Problem> {
        match self.nums(name, &[ty])? {
            None => Ok(None),
            Some((&[v], _)) => Ok(Some(v)),
            Some((v, at)) => Err((
                at,
                format!("`{name}` takes one number, got {}", v.len()),
                None,
            )),
        }
    }

    /// One whole number of type "integer".
    pub fn int(&self, name: &str) -> Result<Option<i64>, Problem> {
        let Some(v) = self.one_num(name, "integer")? else {
            return Ok(None);
        };
        whole(v).map(Some).ok_or_else(|| {
            (
                self.get(name).map_or(
                    At {
                        file: 0,
                        line: 0,
                        col: 0,
                    },
                    |p| p.at,
                ),
                format!("`{name}` must be a whole number, got {v}"),
                None,
            )
        })
    }

    /// The whole numbers of `name` ("integer"), each at least 0.
    pub fn indices(&self, name: &str) -> Result<Option<(Vec<u32>, At)>, Problem> {
        let Some((v, at)) = self.nums(name, &["integer"])? else {
            return Ok(None);
        };
        let mut out = Vec::with_capacity(v.len());
        for &x in v {
            match whole(x) {
                Some(i) if (0..=i64::from(u32::MAX)).contains(&i) => out.push(i as u32),
                _ => {
                    return Err((
                        at,
                        format!(
                            "`{name}` holds {x}, which is no vertex index (a whole number ≥ 0)"
                        ),
                        None,
                    ))
                }
            }
        }
        Ok(Some((out, at)))
    }

    /// Three numbers of one of `types`.
    pub fn triple(&self, name: &str, types: &[&str]) -> Result<Option<[f64; 3]>, Problem> {
        match self.nums(name, types)? {
            None => Ok(None),
            Some((&[x, y, z], _)) => Ok(Some([x, y, z])),
            Some((v, at)) => Err((
                at,
                format!("`{name}` takes 3 numbers, got {}", v.len()),
                None,
            )),
        }
    }

    /// One string of type `ty` ("string" or "texture").
    pub fn string_of(&self, name: &str, ty: &str) -> Result<Option<(&str, At)>, Problem> {
        let Some(p) = self.typed(name, &[ty])? else {
            return Ok(None);
        };
        match &p.values {
            Values::Strs(v) if v.len() == 1 => Ok(Some((&v[0], p.at))),
            _ => Err((p.at, format!("`{name}` takes one string"), None)),
        }
    }

    /// One string of type "string".
    pub fn string(&self, name: &str) -> Result<Option<&str>, Problem> {
        Ok(self.string_of(name, "string")?.map(|(s, _)| s))
    }

    /// One boolean of type "bool".
    pub fn boolean(&self, name: &str) -> Result<Option<bool>, Problem> {
        let Some(p) = self.typed(name, &["bool"])? else {
            return Ok(None);
        };
        match &p.values {
            Values::Bools(v) if v.len() == 1 => Ok(Some(v[0])),
            _ => Err((p.at, format!("`{name}` takes one of true or false"), None)),
        }
    }

    /// A colour or spectrum: "rgb", "spectrum", "blackbody", "texture" (when
    /// `texture` allows) or a plain "float".
    pub fn spectral(&self, name: &str, texture: bool) -> Result<Option<(Spectral, At)>, Problem> {
        let Some(p) = self.get(name) else {
            return Ok(None);
        };
        let bad = |what: &str| Err((p.at, format!("`{name}`: {what}"), None));
        let s = match (canonical(&p.ty), &p.values) {
            ("rgb", Values::Nums(v)) if v.len() == 3 => Spectral::Rgb([v[0], v[1], v[2]]),
            ("rgb", _) => return bad("an \"rgb\" takes 3 numbers"),
            ("spectrum", Values::Nums(v)) if v.len() >= 2 && v.len() % 2 == 0 => {
                Spectral::Samples(v.clone())
            }
            ("spectrum", Values::Strs(v)) if v.len() == 1 => Spectral::Named(v[0].clone()),
            ("spectrum", _) => {
                return bad("a \"spectrum\" takes wavelength-value pairs or one name")
            }
            ("blackbody", Values::Nums(v)) if v.len() == 1 => Spectral::Blackbody(v[0]),
            ("blackbody", _) => return bad("a \"blackbody\" takes one temperature in kelvin"),
            ("texture", Values::Strs(v)) if texture && v.len() == 1 => {
                Spectral::Texture(v[0].clone())
            }
            ("float", Values::Nums(v)) if v.len() == 1 => Spectral::Grey(v[0]),
            (ty, _) => {
                return Err((
                    p.at,
                    format!(
                        "`{name}` is given as \"{ty}\"; expected \"rgb\", \"spectrum\", \"blackbody\"{}",
                        if texture { " or \"texture\"" } else { "" }
                    ),
                    None,
                ))
            }
        };
        Ok(Some((s, p.at)))
    }

    /// A number or a float texture's name.
    pub fn float_or_texture(&self, name: &str) -> Result<Located<Result<f64, String>>, Problem> {
        let Some(p) = self.get(name) else {
            return Ok(None);
        };
        match (p.ty.as_str(), &p.values) {
            ("float", Values::Nums(v)) if v.len() == 1 => Ok(Some((Ok(v[0]), p.at))),
            ("texture", Values::Strs(v)) if v.len() == 1 => Ok(Some((Err(v[0].clone()), p.at))),
            _ => Err((
                p.at,
                format!("`{name}` takes one \"float\" or a \"texture\""),
                None,
            )),
        }
    }

    /// Refuses every parameter not taken, naming those in `known`.
    pub fn finish(&self, what: &str, known: &[&str]) -> Result<(), Problem> {
        let Some(p) = self.list.iter().find(|p| !p.used.get()) else {
            return Ok(());
        };
        let hint = crate::hint::closest(&p.name, known.iter().copied())
            .map(|k| format!("did you mean `{k}`?"));
        let list = if known.is_empty() {
            "it takes none".to_string()
        } else {
            format!("lumen reads {}", known.join(", "))
        };
        Err((
            p.at,
            format!(
                "{what} has no parameter `{}` that lumen reads; {list}",
                p.name
            ),
            hint,
        ))
    }

    /// These parameters followed by `defaults` (pbrt's `Attribute`s) that
    /// they do not set themselves: a directive's own parameters win, and
    /// a default it does not read is not refused.
    pub fn with_defaults<'a>(mut self, defaults: impl Iterator<Item = &'a Param>) -> Params {
        for d in defaults {
            if !self.list.iter().any(|p| p.name == d.name) {
                let mut d = d.clone();
                d.used = Cell::new(true);
                self.list.push(d);
            }
        }
        self
    }

    /// Marks every parameter as taken.
    pub fn ignore_all(&self) {
        for p in &self.list {
            p.used.set(true);
        }
    }

    /// Marks `names` as taken without reading them (what changes nothing
    /// in lumen's image).
    pub fn ignore(&self, names: &[&str]) {
        for n in names {
            let _ = self.get(n);
        }
    }
}

fn canonical(t: &str) -> &str {
    if t == "color" {
        "rgb"
    } else {
        t
    }
}

/// `v` as a whole number, if it is one.
fn whole(v: f64) -> Option<i64> {
    (v.fract() == 0.0 && v.abs() < 9e15).then_some(v as i64)
}
