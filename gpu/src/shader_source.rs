//! The one way a shader's WGSL text is put together: [`assemble`].
//!
//! WGSL has no includes and no preprocessor, yet one module serves several pipelines (single
//! sampled or multisampled textures, a bind group number, an array length). So a shader is
//! assembled from source files with a single, deliberately tiny preprocessor:
//!
//! 1. **Enable directives** first: `enable NAME;` per requested feature (WGSL requires them
//!    before any declaration), e.g. `primitive_index`.
//! 2. **Concatenation**: the sources (the `shaders/` files, in dependency order), joined by
//!    one newline each.
//! 3. **Placeholders**: a substitution point in a WGSL file is written `{{NAME}}`, `NAME` of
//!    ASCII capitals, digits and `_` (e.g. `var prev_ids: {{IDS_TYPE}};` or
//!    `const MAX_SORTED: u32 = {{OIT_MAX_SORTED}}u;`). Each is replaced by the value given
//!    for its name, in one pass (a value is never scanned for placeholders). The syntax
//!    cannot be confused with WGSL, which never writes `{{`.
//!
//! Assembly fails loudly: a placeholder without a value, a value whose name occurs nowhere,
//! a name given twice or a malformed `{{` panics with the shader's and the placeholder's
//! names. The sources are compile-time constants, so such a panic is a programming error that
//! the naga test (which assembles every shader) catches before anything runs.
//!
//! Not everything that varies between pipelines is text: WGSL `override` constants
//! (`SHADING_MODEL` in `common.wgsl`, `READS_ALPHA` in `capture.wgsl`) specialise one
//! compiled module at pipeline creation and stay `override`s. Placeholders are for what an
//! `override` cannot express: types, bind group numbers, array sizes and attributes.

/// Where a placeholder starts.
const OPEN: &str = "{{";
/// Where a placeholder ends.
const CLOSE: &str = "}}";

/// The complete WGSL text of shader `name`: an `enable` directive per entry of `enables`, then
/// `sources` joined by newlines, with every `{{NAME}}` placeholder replaced by its value in
/// `values` (pairs of name and value).
///
/// # Panics
///
/// When a placeholder has no value, a value's name occurs in no source, a name is given twice
/// or a `{{` does not open a well-formed placeholder; the message names the shader and the
/// placeholder.
pub fn assemble(name: &str, enables: &[&str], sources: &[&str], values: &[(&str, &str)]) -> String {
    for (i, (key, _)) in values.iter().enumerate() {
        assert!(
            values[..i].iter().all(|(k, _)| k != key),
            "shader `{name}`: placeholder `{key}` is given twice"
        );
    }
    let mut out = String::new();
    for e in enables {
        out.push_str("enable ");
        out.push_str(e);
        out.push_str(";\n");
    }
    let mut used = vec![false; values.len()];
    for (i, source) in sources.iter().enumerate() {
        if i > 0 {
            out.push('\n');
        }
        fill_into(&mut out, name, source, values, &mut used);
    }
    for ((key, _), used) in values.iter().zip(used) {
        assert!(
            used,
            "shader `{name}`: placeholder `{{{{{key}}}}}` is given a value but occurs in no source"
        );
    }
    out
}

/// The placeholder names of `source` (`{{NAME}}`), in order of appearance, repeats included:
/// empty for a fully assembled shader.
pub fn placeholders(source: &str) -> Vec<&str> {
    let mut names = Vec::new();
    let mut rest = source;
    while let Some(at) = rest.find(OPEN) {
        let after = &rest[at + OPEN.len()..];
        let end = after.find(CLOSE).unwrap_or(after.len());
        names.push(&after[..end]);
        rest = &after[end..];
    }
    names
}

/// Appends `source` to `out` with its placeholders filled from `values`, marking in `used`
/// which values were needed.
fn fill_into(
    out: &mut String,
    name: &str,
    source: &str,
    values: &[(&str, &str)],
    used: &mut [bool],
) {
    let mut rest = source;
    while let Some(at) = rest.find(OPEN) {
        out.push_str(&rest[..at]);
        let after = &rest[at + OPEN.len()..];
        let end = after
            .find(CLOSE)
            .unwrap_or_else(|| panic!("shader `{name}`: a `{{{{` is never closed by `}}}}`"));
        let key = &after[..end];
        assert!(
            !key.is_empty()
                && key
                    .chars()
                    .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_'),
            "shader `{name}`: `{{{{{key}}}}}` is not a placeholder (NAME of capitals, digits, _)"
        );
        let index = values
            .iter()
            .position(|(k, _)| *k == key)
            .unwrap_or_else(|| panic!("shader `{name}`: placeholder `{{{{{key}}}}}` is unfilled"));
        used[index] = true;
        out.push_str(values[index].1);
        rest = &after[end + CLOSE.len()..];
    }
    out.push_str(rest);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn enables_then_joined_sources_then_filled() {
        let s = assemble(
            "t",
            &["primitive_index"],
            &["const A: u32 = {{N}}u;", "var x: {{T}};\n"],
            &[("N", "4"), ("T", "f32")],
        );
        assert_eq!(
            s,
            "enable primitive_index;\nconst A: u32 = 4u;\nvar x: f32;\n"
        );
        assert!(placeholders(&s).is_empty());
    }

    #[test]
    fn a_value_is_not_rescanned() {
        let s = assemble("t", &[], &["{{A}}"], &[("A", "{{B}}")]);
        assert_eq!(s, "{{B}}");
        assert_eq!(placeholders(&s), ["B"]);
    }

    #[test]
    #[should_panic(expected = "shader `t`: placeholder `{{N}}` is unfilled")]
    fn an_unfilled_placeholder_panics() {
        assemble("t", &[], &["const A: u32 = {{N}}u;"], &[]);
    }

    #[test]
    #[should_panic(expected = "shader `t`: placeholder `{{M}}` is given a value but occurs")]
    fn an_unused_value_panics() {
        assemble(
            "t",
            &[],
            &["const A: u32 = {{N}}u;"],
            &[("N", "1"), ("M", "2")],
        );
    }

    #[test]
    #[should_panic(expected = "is never closed")]
    fn an_unclosed_placeholder_panics() {
        assemble("t", &[], &["{{N"], &[]);
    }

    #[test]
    #[should_panic(expected = "is not a placeholder")]
    fn a_malformed_placeholder_panics() {
        assemble("t", &[], &["{{ n }}"], &[]);
    }

    #[test]
    #[should_panic(expected = "given twice")]
    fn a_name_given_twice_panics() {
        assemble("t", &[], &["{{N}}"], &[("N", "1"), ("N", "2")]);
    }
}
