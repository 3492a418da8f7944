//! What the server says of a grammar parameter (`param NAME = DEFAULT in LO..HI`): its value,
//! default and range, in hovers and in the details of completions. The numbers are the
//! compiler's: the file's `let` and `param` declarations alone, printed and compiled, give the
//! grammar's `params` list (a parameter's default and range may use only numbers, built-ins
//! and `let`s, E072, so they fold without the rest of the file, whatever its state).

use clay_dsl::analysis::{Analysis, SymbolKind};
use clay_dsl::compiled::{Param, ParamKind};
use clay_dsl::format_number;
use clay_dsl::syntax::{File, Item};

/// The parameters declared in `text` (one file, its imports aside), in declaration order;
/// `None` when the text does not parse or its constants do not compile on their own.
pub fn declared(text: &str) -> Option<Vec<Param>> {
    let tree = clay_dsl::parse(text).ok()?;
    if !tree.items.iter().any(|i| matches!(i, Item::Param(_))) {
        return Some(Vec::new());
    }
    let constants = File {
        items: (tree.items.into_iter())
            .filter(|i| matches!(i, Item::Let(_) | Item::Param(_)))
            .collect(),
        span: tree.span,
    };
    let printed = clay_dsl::print_file(&constants);
    let compiled = clay_dsl::compile(
        &printed,
        "<parameters>",
        &clay_dsl::CompileOptions::default(),
    )
    .ok()?;
    Some(compiled.grammar.params)
}

/// The parameter symbol `i` of `a` is, if it is one: its declaration in its own file's text
/// starts with `param`. Gives the declaring file's text and the parameter's name.
pub fn symbol_param(a: &Analysis, i: usize) -> Option<(&str, &str)> {
    let sym = a.symbols().symbols.get(i)?;
    if sym.kind != SymbolKind::Constant {
        return None;
    }
    let place = a.place(sym.full);
    let text = a.file_index(place.file)?.text();
    let declaration = text.get(place.span.start..place.span.end)?;
    declaration
        .trim_start()
        .starts_with("param")
        .then_some((text, sym.name.as_str()))
}

/// `2..12`, or what a parameter declared without a range takes.
fn range(p: &Param) -> String {
    match (&p.kind, p.range) {
        (_, Some([low, high])) => format!("`{}..{}`", format_number(low), format_number(high)),
        (ParamKind::Number, None) => "any finite number".to_string(),
        (ParamKind::Int, None) => "any whole number".to_string(),
        (ParamKind::Seed, None) => "any whole number from 0".to_string(),
        (ParamKind::Bool, None) => "`true` or `false`".to_string(),
        (ParamKind::Choice { choices }, None) => {
            let all: Vec<String> = choices.iter().map(|c| format!("`{c}`")).collect();
            format!("one of {}", all.join(", "))
        }
    }
}

/// `parameter`, or `int parameter` (and so on) for a typed one.
fn kind(p: &Param) -> String {
    match p.kind {
        ParamKind::Number => "parameter".to_string(),
        ref k => format!("{} parameter", k.word()),
    }
}

/// The hover's paragraph on a parameter (markdown).
pub fn hover(p: &Param) -> String {
    format!(
        "\n**{}**: value `{}`, default `{}`, range {}; set it when compiling \
         (`clayc run FILE --param {}=VALUE`)\n",
        kind(p),
        p.value,
        p.default,
        range(p),
        p.name
    )
}

/// A completion's detail for a parameter.
pub fn detail(p: &Param) -> String {
    format!(
        "{} = {} (default {}, range {})",
        kind(p),
        p.value,
        p.default,
        range(p).trim_matches('`')
    )
}

/// Every parameter `a` can see: its own file's (from `text`, or from `fallback` when `text`
/// does not parse) and those of the files it imports.
pub fn visible(a: &Analysis, fallback: Option<&str>) -> Vec<Param> {
    let own = declared(a.text()).or_else(|| fallback.and_then(declared));
    let mut all = own.unwrap_or_default();
    let mut file = 1;
    while let Some(index) = a.file_index(file) {
        all.extend(declared(index.text()).unwrap_or_default());
        file += 1;
    }
    all
}

#[cfg(test)]
mod tests {
    use super::declared;

    #[test]
    fn defaults_and_ranges_fold_whatever_the_rest_of_the_file_says() {
        let text = "let k = 2\nparam a = k + 1 in 0..k * 3\nparam b = 5\n\
                    piece p { vertex v (a, nowhere) }\nmodel { x = nothing }\n";
        let params = declared(text).unwrap();
        assert_eq!(params.len(), 2);
        assert_eq!(
            (params[0].value.number(), params[0].default.number()),
            (Some(3.0), Some(3.0))
        );
        assert_eq!(params[0].range, Some([0.0, 6.0]));
        assert_eq!((params[1].name.as_str(), params[1].range), ("b", None));
        assert_eq!(declared("piece {").map(|p| p.len()), None);
        assert_eq!(declared("let k = 1\n").map(|p| p.len()), Some(0));
    }

    #[test]
    fn a_typed_parameter_says_its_type_and_values() {
        let text =
            "param t: bool = true\nparam g: choice(\"a\", \"b\") = \"b\"\nparam n: int = 3\n";
        let params = declared(text).unwrap();
        let hovers: Vec<String> = params.iter().map(super::hover).collect();
        assert!(
            hovers[0].contains(
                "**bool parameter**: value `true`, default `true`, range `true` or `false`"
            ),
            "{hovers:?}"
        );
        assert!(
            hovers[1].contains("value `b`, default `b`, range one of `a`, `b`"),
            "{hovers:?}"
        );
        assert!(
            hovers[2].contains("**int parameter**: value `3`"),
            "{hovers:?}"
        );
        assert_eq!(
            super::detail(&params[2]),
            "int parameter = 3 (default 3, range any whole number)"
        );
    }
}
