//! Text that every SVG renderer sets alike.
//!
//! The SVG backend aligns text vertically with `dy` in font-relative units (`0.76em`,
//! `0.5ex`, `-0.5ex`). Renderers disagree on `ex` (the x-height of whichever font they found,
//! or half an em), and some misplace rotated text that carries a `dy`. [`portable_text`]
//! bakes every such offset into the element's `y` in pixels, taking `1ex = 0.5em` as CSS does
//! when a font gives no x-height, and trims the line breaks around each text, so that what
//! a browser and librsvg draw is the same.

/// `svg` with every `<text>`'s relative `dy` folded into its `y` and its content trimmed.
pub(super) fn portable_text(svg: &str) -> String {
    let mut out = String::with_capacity(svg.len());
    let mut rest = svg;
    while let Some(start) = rest.find("<text ") {
        out.push_str(&rest[..start]);
        rest = &rest[start..];
        let Some(tag_end) = rest.find('>') else {
            break;
        };
        let tag = &rest[..tag_end];
        out.push_str(&baked_tag(tag));
        out.push('>');
        rest = &rest[tag_end + 1..];
        if let Some(close) = rest.find("</text>") {
            out.push_str(rest[..close].trim());
            rest = &rest[close..];
        }
    }
    out.push_str(rest);
    out
}

/// The value of attribute `name` in `tag`, with the byte range of the whole `name="value"`.
fn attribute<'a>(tag: &'a str, name: &str) -> Option<(&'a str, std::ops::Range<usize>)> {
    let key = format!(" {name}=\"");
    let at = tag.find(&key)?;
    let value_start = at + key.len();
    let len = tag[value_start..].find('"')?;
    Some((
        &tag[value_start..value_start + len],
        at..value_start + len + 1,
    ))
}

/// An opening `<text ...` tag (without its `>`) with its relative `dy` folded into `y`.
fn baked_tag(tag: &str) -> String {
    let (Some((dy, dy_range)), Some((y, y_range)), Some((size, _))) = (
        attribute(tag, "dy"),
        attribute(tag, "y"),
        attribute(tag, "font-size"),
    ) else {
        return tag.to_string();
    };
    let em = if let Some(v) = dy.strip_suffix("em") {
        v.parse::<f64>().ok()
    } else if let Some(v) = dy.strip_suffix("ex") {
        v.parse::<f64>().ok().map(|v| 0.5 * v)
    } else {
        None
    };
    let (Some(em), Ok(y), Ok(size)) = (em, y.parse::<f64>(), size.parse::<f64>()) else {
        return tag.to_string();
    };
    let baked = format!(" y=\"{}\"", round(y + em * size));
    // Replace the later attribute first so that the earlier range stays valid.
    let mut out = tag.to_string();
    if dy_range.start > y_range.start {
        out.replace_range(dy_range, "");
        out.replace_range(y_range, &baked);
    } else {
        out.replace_range(y_range, &baked);
        out.replace_range(dy_range, "");
    }
    out
}

/// `v` to a hundredth of a pixel, without trailing zeros.
fn round(v: f64) -> String {
    let s = format!("{:.2}", v);
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_offsets_become_pixels() {
        let svg = concat!(
            "<svg><text x=\"10\" y=\"20\" dy=\"0.76em\" font-size=\"10\">\nTitle\n</text>",
            "<text x=\"1\" y=\"5\" dy=\"-0.5ex\" text-anchor=\"end\" font-size=\"20\" ",
            "transform=\"rotate(270, 1, 5)\">\nlabel\n</text></svg>"
        );
        let out = portable_text(svg);
        assert_eq!(
            out,
            concat!(
                "<svg><text x=\"10\" y=\"27.6\" font-size=\"10\">Title</text>",
                "<text x=\"1\" y=\"0\" text-anchor=\"end\" font-size=\"20\" ",
                "transform=\"rotate(270, 1, 5)\">label</text></svg>"
            )
        );
        assert!(!out.contains("dy="));
    }

    #[test]
    fn text_without_a_relative_offset_is_kept() {
        let svg = "<text x=\"1\" y=\"2\" font-size=\"3\">a &lt; b</text><rect/>";
        assert_eq!(portable_text(svg), svg);
        assert_eq!(portable_text("<svg/>"), "<svg/>");
    }
}
