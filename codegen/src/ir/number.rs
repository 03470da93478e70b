//! Exact numbers of the model file: parameter values and initial values.

use super::Rational;
use super::file::Number;

/// An exact rational from a TOML value: an integer, a string "p/q", an
/// integer string, or a decimal (as a string or a TOML float), read exactly.
/// An initial value: an exact number, or one times `pi` (`pi/2`, `-3*pi/4`).
pub(super) fn initial_value(n: &Number) -> Result<f64, String> {
    let Number::Text(t) = n else {
        return rational(n).map(Rational::to_f64);
    };
    let t: String = t.chars().filter(|c| !c.is_whitespace()).collect();
    let Some((before, after)) = t.split_once("pi") else {
        return rational(n).map(Rational::to_f64);
    };
    let coefficient = match before.strip_suffix('*').unwrap_or(before) {
        "" => 1.0,
        "-" => -1.0,
        c => rational(&Number::Text(c.to_string()))?.to_f64(),
    };
    let divisor = match after.strip_prefix('/') {
        None if after.is_empty() => 1.0,
        Some(d) => rational(&Number::Text(d.to_string()))?.to_f64(),
        None => {
            return Err(format!(
                "`{t}`: write a rational multiple of pi such as `pi/2` or `-3*pi/4`"
            ));
        }
    };
    if divisor == 0.0 {
        return Err(format!("`{t}` divides by zero"));
    }
    Ok(coefficient * std::f64::consts::PI / divisor)
}

pub(super) fn rational(n: &Number) -> Result<Rational, String> {
    let text = match n {
        Number::Int(i) => {
            return Ok(Rational {
                num: *i as i128,
                den: 1,
            });
        }
        Number::Float(f) if !f.is_finite() => {
            return Err(format!("{f} is not a finite number"));
        }
        // A TOML float's shortest round-trip text is the number the user wrote.
        Number::Float(f) => format!("{f}"),
        Number::Text(t) => t.trim().to_string(),
    };
    let parse_int = |s: &str| -> Result<i128, String> {
        s.trim().parse::<i128>().map_err(|_| {
            format!(
                "`{text}` is not an exact number (write an integer, a fraction p/q or a decimal)"
            )
        })
    };
    let (num, den) = if let Some((p, q)) = text.split_once('/') {
        (parse_int(p)?, parse_int(q)?)
    } else if let Some((whole, frac)) = text.split_once('.') {
        if frac.is_empty() || !frac.chars().all(|c| c.is_ascii_digit()) || frac.len() > 18 {
            return Err(format!("`{text}` is not an exact decimal"));
        }
        let den = 10i128.pow(frac.len() as u32);
        let negative = whole.trim().starts_with('-');
        let w = if whole.trim() == "-" || whole.trim().is_empty() {
            0
        } else {
            parse_int(whole)?
        };
        let f = parse_int(frac)?;
        let num = w
            .checked_mul(den)
            .and_then(|x| {
                if negative {
                    x.checked_sub(f)
                } else {
                    x.checked_add(f)
                }
            })
            .ok_or_else(|| format!("`{text}` is too large"))?;
        (num, den)
    } else {
        (parse_int(&text)?, 1)
    };
    if den == 0 {
        return Err(format!("`{text}` divides by zero"));
    }
    let g = gcd(num.unsigned_abs(), den.unsigned_abs()) as i128;
    let (num, den) = (num / g, den / g);
    let (num, den) = if den < 0 { (-num, -den) } else { (num, den) };
    if num.unsigned_abs() > 1u128 << 60 || den > 1i128 << 60 {
        return Err(format!("`{text}` has a numerator or denominator too large"));
    }
    Ok(Rational { num, den })
}

fn gcd(mut a: u128, mut b: u128) -> u128 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a.max(1)
}
