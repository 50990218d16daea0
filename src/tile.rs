//! Tiles: rectangles of an image's pixels, so that a render whose film is
//! too large for one machine can be split by pixel region
//! (`render --tile`, `render --part K/N --split tiles`) and its parts
//! joined by `lumen merge`.
//!
//! A pixel's samples do not depend on the tile it is rendered in (its
//! random numbers are addressed by its place in the whole image), so the
//! tiles of a render put together are the one-machine image to the bit.

use std::fmt;
use std::str::FromStr;

/// The pixels `x0..x1` × `y0..y1` of an image (columns from the left, rows
/// from the top).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Tile {
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// Column after the last.
    pub x1: u32,
    /// Row after the last.
    pub y1: u32,
}

impl Tile {
    /// Every pixel of a `width`×`height` image.
    pub fn whole(width: u32, height: u32) -> Self {
        Tile {
            x0: 0,
            y0: 0,
            x1: width,
            y1: height,
        }
    }

    /// Band `index` of `count` bands of whole rows of a `width`×`height`
    /// image: rows `⌊index·height/count⌋..⌊(index+1)·height/count⌋`. `None`
    /// when there are more bands than rows (some would be empty).
    pub fn band(index: u32, count: u32, width: u32, height: u32) -> Option<Self> {
        if count == 0 || index >= count || count > height {
            return None;
        }
        let at = |k: u32| (u64::from(k) * u64::from(height) / u64::from(count)) as u32;
        Some(Tile {
            x0: 0,
            y0: at(index),
            x1: width,
            y1: at(index + 1),
        })
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.x1 - self.x0
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.y1 - self.y0
    }

    /// Number of pixels.
    pub fn area(&self) -> u64 {
        u64::from(self.width()) * u64::from(self.height())
    }

    /// Whether this tile is every pixel of a `width`×`height` image.
    pub fn is_whole(&self, width: u32, height: u32) -> bool {
        *self == Tile::whole(width, height)
    }

    /// Whether this tile holds pixels and lies within a `width`×`height`
    /// image; the error says what is wrong.
    pub fn check_within(&self, width: u32, height: u32) -> Result<(), String> {
        if self.x0 >= self.x1 || self.y0 >= self.y1 {
            return Err(format!(
                "tile {self} holds no pixels (it needs X0 < X1 and Y0 < Y1)"
            ));
        }
        if self.x1 > width || self.y1 > height {
            return Err(format!(
                "tile {self} reaches beyond the {width}x{height} image"
            ));
        }
        Ok(())
    }

    /// The pixels this tile shares with `other`, if any.
    pub fn overlap(&self, other: &Tile) -> Option<Tile> {
        let t = Tile {
            x0: self.x0.max(other.x0),
            y0: self.y0.max(other.y0),
            x1: self.x1.min(other.x1),
            y1: self.y1.min(other.y1),
        };
        (t.x0 < t.x1 && t.y0 < t.y1).then_some(t)
    }
}

impl fmt::Display for Tile {
    /// `X0,Y0,X1,Y1`, as `--tile` takes it.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{},{},{},{}", self.x0, self.y0, self.x1, self.y1)
    }
}

impl FromStr for Tile {
    type Err = String;

    /// `X0,Y0,X1,Y1`: the pixels `X0..X1` × `Y0..Y1`.
    fn from_str(text: &str) -> Result<Self, String> {
        let bad = || {
            format!(
                "'{text}': a tile is X0,Y0,X1,Y1, the pixels X0..X1 x Y0..Y1 (e.g. 0,0,960,540)"
            )
        };
        let v: Vec<u32> = text
            .split(',')
            .map(|p| p.trim().parse::<u32>().map_err(|_| bad()))
            .collect::<Result<_, _>>()?;
        let &[x0, y0, x1, y1] = v.as_slice() else {
            return Err(bad());
        };
        let tile = Tile { x0, y0, x1, y1 };
        if x0 >= x1 || y0 >= y1 {
            return Err(format!(
                "'{text}': tile {tile} holds no pixels (it needs X0 < X1 and Y0 < Y1)"
            ));
        }
        Ok(tile)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bands_cover_every_row_once() {
        for height in [1, 2, 7, 64, 1080] {
            for count in [1, 2, 3, 7, 64] {
                if count > height {
                    assert_eq!(Tile::band(0, count, 5, height), None);
                    continue;
                }
                let mut at = 0;
                for index in 0..count {
                    let t = Tile::band(index, count, 5, height).unwrap();
                    assert_eq!(
                        (t.x0, t.x1, t.y0),
                        (0, 5, at),
                        "{index}/{count} of {height}"
                    );
                    assert!(t.y1 > t.y0);
                    at = t.y1;
                }
                assert_eq!(at, height);
            }
        }
    }

    #[test]
    fn tiles_parse_and_refuse_with_the_reason() {
        let t: Tile = "0, 10,20,30".parse().unwrap();
        assert_eq!((t.x0, t.y0, t.x1, t.y1), (0, 10, 20, 30));
        assert_eq!(t.to_string(), "0,10,20,30");
        assert_eq!(t.area(), 400);
        let err = |s: &str| s.parse::<Tile>().unwrap_err();
        for bad in ["", "1,2,3", "1,2,3,4,5", "a,0,1,1", "-1,0,1,1"] {
            assert!(
                err(bad).contains("a tile is X0,Y0,X1,Y1"),
                "{bad}: {}",
                err(bad)
            );
        }
        assert!(err("5,0,5,1").contains("no pixels"));
        assert!(t.check_within(20, 30).is_ok());
        assert!(t
            .check_within(19, 30)
            .unwrap_err()
            .contains("beyond the 19x30"));
    }

    #[test]
    fn overlaps_are_the_shared_pixels() {
        let a = Tile::whole(10, 10);
        let b: Tile = "5,5,15,15".parse().unwrap();
        assert_eq!(a.overlap(&b), Some("5,5,10,10".parse().unwrap()));
        let c: Tile = "10,0,12,10".parse().unwrap();
        assert_eq!(a.overlap(&c), None);
    }
}
