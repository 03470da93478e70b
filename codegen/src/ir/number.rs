//! Exact numbers of the model file: parameter values and initial values.

use super::Rational;
use super::file::Number;

/// An exact rational from a TOML value: an integer, a string "p/q", an
/// integer string, or a decimal (as a string or a TOML float), read exactly.
pub(super) fn rational(n: &Number) -> Result<Rational, String> {
    let text = match n {
        Number::Int(i) => return bounded(*i as i128, 1).ok_or_else(|| format!("{i} is too large")),
        Number::Float(f) if !f.is_finite() => {
            return Err(format!("{f} is not a finite number"));
        }
        // A TOML float's shortest round-trip text is the number the user wrote.
        Number::Float(f) => format!("{f}"),
        Number::Text(t) => t.trim().to_string(),
    };
    match text.split_once('/') {
        Some((p, q)) => {
            let p = signed_decimal(p.trim())?;
            let q = signed_decimal(q.trim())?;
            if q.num == 0 {
                return Err(format!("`{text}` divides by zero"));
            }
            checked_div(p, q).ok_or_else(|| format!("`{text}` is too large"))
        }
        None => signed_decimal(&text),
    }
    .map_err(|why| {
        if why.contains("too large") {
            why
        } else {
            format!(
                "`{text}` is not an exact number (write an integer, a fraction p/q or a decimal)"
            )
        }
    })
}

/// An optionally signed decimal number.
fn signed_decimal(t: &str) -> Result<Rational, String> {
    match t.strip_prefix('-') {
        Some(rest) => decimal(rest.trim()).map(|r| Rational {
            num: -r.num,
            den: r.den,
        }),
        None => decimal(t.strip_prefix('+').unwrap_or(t).trim()),
    }
}

/// Largest numerator or denominator of an exact number: far inside i128, so
/// that products of two never overflow before they are checked.
const MAX_PART: i128 = 1 << 60;

/// An unsigned decimal literal, exactly: `12`, `0.25`, `.5`, `1e-3`,
/// `2.5E4`.
pub(super) fn decimal(t: &str) -> Result<Rational, String> {
    let bad = || format!("`{t}` is not a number");
    let (mantissa, exponent) = match t.find(['e', 'E']) {
        Some(i) => (&t[..i], Some(&t[i + 1..])),
        None => (t, None),
    };
    let (whole, frac) = mantissa.split_once('.').unwrap_or((mantissa, ""));
    if whole.is_empty() && frac.is_empty()
        || !whole
            .bytes()
            .chain(frac.bytes())
            .all(|c| c.is_ascii_digit())
    {
        return Err(bad());
    }
    let digits = format!("{whole}{frac}");
    let digits = digits.trim_start_matches('0');
    if digits.len() > 18 {
        return Err(format!(
            "`{t}` is too large or too precise (at most 18 digits)"
        ));
    }
    let mut power: i64 = -(frac.len() as i64);
    if let Some(e) = exponent {
        let e: i64 = e.parse().map_err(|_| bad())?;
        if e.abs() > 18 {
            return Err(format!(
                "`{t}` is too large or too small (exponents up to 18)"
            ));
        }
        power += e;
    }
    let n: i128 = if digits.is_empty() {
        0
    } else {
        digits.parse().map_err(|_| bad())?
    };
    let scale = 10i128.pow(power.unsigned_abs() as u32);
    let r = if power >= 0 {
        bounded(n * scale, 1)
    } else {
        bounded(n, scale)
    };
    r.ok_or_else(|| format!("`{t}` is too large (at most about 1e18)"))
}

/// p/q in lowest terms with q > 0, when both fit the bounds.
fn bounded(num: i128, den: i128) -> Option<Rational> {
    if den == 0
        || num.checked_abs()? > MAX_PART * MAX_PART
        || den.checked_abs()? > MAX_PART * MAX_PART
    {
        return None;
    }
    let g = gcd(num.unsigned_abs(), den.unsigned_abs()) as i128;
    let (num, den) = (num / g, den / g);
    let (num, den) = if den < 0 { (-num, -den) } else { (num, den) };
    (num.abs() <= MAX_PART && den <= MAX_PART).then_some(Rational { num, den })
}

/// a + b, if it fits.
pub(super) fn checked_add(a: Rational, b: Rational) -> Option<Rational> {
    let num = a
        .num
        .checked_mul(b.den)?
        .checked_add(b.num.checked_mul(a.den)?)?;
    bounded(num, a.den.checked_mul(b.den)?)
}

/// a · b, if it fits.
pub(super) fn checked_mul(a: Rational, b: Rational) -> Option<Rational> {
    bounded(a.num.checked_mul(b.num)?, a.den.checked_mul(b.den)?)
}

/// a / b, if b ≠ 0 and it fits.
pub(super) fn checked_div(a: Rational, b: Rational) -> Option<Rational> {
    bounded(a.num.checked_mul(b.den)?, a.den.checked_mul(b.num)?)
}

/// aⁿ, if it fits (a ≠ 0 when n < 0).
pub(super) fn checked_pow(a: Rational, n: i128) -> Option<Rational> {
    let k = n.unsigned_abs();
    let out = if a.num.abs() == a.den || a.num == 0 {
        // ±1 and 0: any power, by parity.
        let negative = a.num < 0 && k % 2 == 1;
        let unit = if a.num == 0 && k > 0 { 0 } else { 1 };
        Rational {
            num: if negative { -unit } else { unit },
            den: 1,
        }
    } else if k > 128 {
        return None;
    } else {
        (0..k).try_fold(Rational { num: 1, den: 1 }, |acc, _| checked_mul(acc, a))?
    };
    if n < 0 {
        checked_div(Rational { num: 1, den: 1 }, out)
    } else {
        Some(out)
    }
}

fn gcd(mut a: u128, mut b: u128) -> u128 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a.max(1)
}
