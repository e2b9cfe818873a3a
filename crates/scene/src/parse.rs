//! The text forms of values on command lines and in scene files.

use std::path::PathBuf;

use crate::values::Colour;

/// A colour: one finite number "x" (grey) or three "r,g,b".
pub fn colour(s: &str) -> Result<Colour, String> {
    if s.contains(',') {
        let [r, g, b] = triple(s)?;
        return Ok(Colour::Rgb([r as f32, g as f32, b as f32]));
    }
    match s.trim().parse::<f32>() {
        Ok(v) if v.is_finite() => Ok(Colour::Grey(v)),
        _ => Err(format!("expected a number or r,g,b, got {s:?}")),
    }
}

/// Three finite numbers "x,y,z" (a leading minus is fine).
pub fn triple(s: &str) -> Result<[f64; 3], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|c| c.trim().parse::<f64>().map_err(|e| format!("{s:?}: {e}")))
        .collect::<Result<_, _>>()?;
    match v[..] {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok([x, y, z]),
        _ => Err(format!("expected three finite numbers x,y,z, got {s:?}")),
    }
}

/// Three finite numbers "x,y,z" as an `f32` vector (directions, colours).
pub fn vector(s: &str) -> Result<[f32; 3], String> {
    triple(s).map(|v| v.map(|c| c as f32))
}

/// A shutter `OPEN,CLOSE` in frames (`-0.25,0.25`), open <= close.
pub fn shutter(s: &str) -> Result<[f32; 2], String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let [a, b] = parts[..] else {
        return Err(format!("shutter {s:?}: expected OPEN,CLOSE (frames)"));
    };
    let num = |x: &str| {
        x.parse::<f32>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("shutter {s:?}: {x:?} is not a finite number"))
    };
    let (open, close) = (num(a)?, num(b)?);
    if close < open {
        return Err(format!("shutter {s:?}: open must not be after close"));
    }
    Ok([open, close])
}

/// "WxH", each side 1 to 16384.
pub fn resolution(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WxH, got {s:?}"))?;
    let w: u32 = w.parse().map_err(|e| format!("{s:?}: {e}"))?;
    let h: u32 = h.parse().map_err(|e| format!("{s:?}: {e}"))?;
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err(format!(
            "resolution {w}x{h} must be between 1 and 16384 a side"
        ));
    }
    Ok((w, h))
}

/// A resolution field of a scene file or a JSON dict: "WxH".
pub fn resolution_field<'de, D: serde::Deserializer<'de>>(
    d: D,
) -> Result<Option<(u32, u32)>, D::Error> {
    let s = <String as serde::Deserialize>::deserialize(d)?;
    resolution(&s).map(Some).map_err(serde::de::Error::custom)
}

/// A 3-vector field of a scene file or a JSON dict: exactly three
/// numbers. (Serde reads an array `[T; 3]` as the first three elements
/// of a list and drops the rest, so `[1, 2, 3, 4]` would pass unseen.)
pub fn triple_field<'de, D, T>(d: D) -> Result<Option<[T; 3]>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: serde::Deserialize<'de>,
{
    let v = <Vec<T> as serde::Deserialize>::deserialize(d)?;
    let n = v.len();
    <[T; 3]>::try_from(v)
        .map(Some)
        .map_err(|_| serde::de::Error::custom(format!("expected 3 numbers, got {n}")))
}

/// "x0,y0,x1,y1" in pixels.
pub fn crop(s: &str) -> Result<[u32; 4], String> {
    let v: Vec<u32> = s
        .split(',')
        .map(|c| c.trim().parse::<u32>().map_err(|e| format!("{s:?}: {e}")))
        .collect::<Result<_, _>>()?;
    match v[..] {
        [x0, y0, x1, y1] => Ok([x0, y0, x1, y1]),
        _ => Err(format!("expected x0,y0,x1,y1, got {s:?}")),
    }
}

/// `FILE.exr[:CHANNEL]` split into the file and the channel.
pub fn split_depth_spec(spec: &str) -> (PathBuf, Option<String>) {
    match spec.rsplit_once(':') {
        Some((file, channel)) if !channel.is_empty() && !channel.contains('/') => {
            (PathBuf::from(file), Some(channel.to_string()))
        }
        _ => (PathBuf::from(spec), None),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colours_are_one_number_or_three() {
        assert_eq!(colour("0.5"), Ok(Colour::Grey(0.5)));
        assert_eq!(colour("1, 2,3"), Ok(Colour::Rgb([1.0, 2.0, 3.0])));
        for bad in ["", "x", "1,2", "1,2,3,4", "nan", "inf", "1,nan,2"] {
            assert!(colour(bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn text_forms_parse_and_refuse() {
        assert_eq!(triple("1,-2.5, 3").unwrap(), [1.0, -2.5, 3.0]);
        assert!(triple("1,2").is_err());
        assert!(triple("1,2,nan").is_err());
        assert_eq!(shutter("-0.25, 0.25").unwrap(), [-0.25, 0.25]);
        assert_eq!(shutter("0,0").unwrap(), [0.0, 0.0]);
        assert!(shutter("0.5,0.25").unwrap_err().contains("after"));
        assert!(shutter("0").is_err() && shutter("0,inf").is_err());
        assert_eq!(resolution("640x360").unwrap(), (640, 360));
        assert_eq!(resolution("8X4").unwrap(), (8, 4));
        assert!(resolution("0x4").is_err());
        assert!(resolution("16385x4").is_err());
        assert!(resolution("12by4").unwrap_err().contains("WxH"));
        assert_eq!(crop("1,2,30,40").unwrap(), [1, 2, 30, 40]);
        assert!(crop("1,2,3").is_err());
    }

    #[test]
    fn a_depth_spec_splits_at_its_channel() {
        assert_eq!(split_depth_spec("z.exr"), (PathBuf::from("z.exr"), None));
        let (f, c) = split_depth_spec("dir/z.exr:ViewLayer.Depth.Z");
        assert_eq!(
            (f, c.as_deref()),
            (PathBuf::from("dir/z.exr"), Some("ViewLayer.Depth.Z"))
        );
    }
}
