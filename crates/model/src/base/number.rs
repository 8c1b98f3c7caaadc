//! Numbers as messages show them: one helper, [`shown`], for the points, lengths and values
//! printed in messages, so that no input of any magnitude prints hundreds of digits (`{}` of
//! 1e308 is a 309-digit integer, of 1e-150 a decimal with 150 zeros).

/// `v` in plain decimal (`{}`, the shortest text that reads back as `v`) when 1e-4 <= |v| < 1e9
/// or v is 0; in scientific notation (`{:e}`, as 1e308 or 1.25e-150) otherwise. Non-finite
/// values print as Rust does (inf, -inf, NaN).
pub fn shown(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1e-4..1e9).contains(&v.abs()) { format!("{v}") } else { format!("{v:e}") }
}

/// A point `(x, y)`, each coordinate [`shown`].
pub fn point(p: [f64; 2]) -> String {
    format!("({}, {})", shown(p[0]), shown(p[1]))
}

/// `v` to 6 significant digits without trailing zeros (0.1875, 0.254745): an arc length in the
/// summary, not the 17 digits of a point on a curved Gmsh boundary (`--json` keeps those). In
/// scientific notation (1.25e150) where [`shown`] would be.
pub fn significant(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return v.to_string();
    }
    if !(1e-4..1e9).contains(&v.abs()) {
        let s = format!("{v:.5e}");
        let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
        let mantissa = if mantissa.contains('.') { mantissa.trim_end_matches('0').trim_end_matches('.') } else { mantissa };
        return format!("{mantissa}e{exponent}");
    }
    let decimals = (5 - v.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.').to_string() } else { s }
}

#[cfg(test)]
mod tests {
    use super::shown;

    #[test]
    fn moderate_values_are_plain_and_extreme_ones_scientific() {
        for (v, s) in [
            (0.5, "0.5"),
            (-0.25, "-0.25"),
            (0.0, "0"),
            (123456.5, "123456.5"),
            (1e-4, "0.0001"),
            (1e308, "1e308"),
            (-1.25e-150, "-1.25e-150"),
            (1e9, "1e9"),
            (f64::INFINITY, "inf"),
        ] {
            assert_eq!(shown(v), s);
        }
        assert_eq!(super::point([0.5, 1e308]), "(0.5, 1e308)");
        for v in [1e-300, 3.3e200, 7e-5, 2.5e12] {
            assert_eq!(shown(v).parse::<f64>().unwrap(), v, "reads back");
            assert!(shown(v).len() < 12, "{}", shown(v));
        }
    }

    #[test]
    fn arc_lengths_of_any_size_print_in_a_few_characters() {
        for (v, s) in [(0.1875, "0.1875"), (0.2547452048856056, "0.254745"), (1.0, "1"), (1.25e150, "1.25e150"), (-2.5e-150, "-2.5e-150")] {
            assert_eq!(super::significant(v), s);
        }
    }
}
