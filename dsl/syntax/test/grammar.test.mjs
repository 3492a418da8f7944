// Tests dsl/syntax/clay.tmLanguage.json with VS Code's own TextMate engine (vscode-textmate on
// vscode-oniguruma) on every example grammar (grammars/*.clay), every ```clay block of
// docs/language.md and fixture.clay (the syntax the examples do not show yet).
//
// Run: cd dsl/syntax/test && npm ci && node --test
//
// The generic checks compare the engine's scopes with a small reference lexer written here
// (comments, strings, colours, numbers, names, punctuation) and with the statement structure of
// docs/language.md; the hand-written ones at the end pin particular tokens.

import { test } from "node:test";
import assert from "node:assert/strict";
import { readFileSync, readdirSync } from "node:fs";
import { createRequire } from "node:module";
import path from "node:path";
import { fileURLToPath } from "node:url";
import vsctm from "vscode-textmate";
import oniguruma from "vscode-oniguruma";

const require = createRequire(import.meta.url);
const here = path.dirname(fileURLToPath(import.meta.url));
const root = path.resolve(here, "../../..");
const grammarPath = path.join(root, "dsl/syntax/clay.tmLanguage.json");
const grammarText = readFileSync(grammarPath, "utf8");

const wasm = readFileSync(require.resolve("vscode-oniguruma/release/onig.wasm"));
await oniguruma.loadWASM(wasm.buffer.slice(wasm.byteOffset, wasm.byteOffset + wasm.byteLength));
const registry = new vsctm.Registry({
  onigLib: Promise.resolve({
    createOnigScanner: (patterns) => new oniguruma.OnigScanner(patterns),
    createOnigString: (s) => new oniguruma.OnigString(s),
  }),
  loadGrammar: async (scopeName) =>
    scopeName === "source.clay" ? vsctm.parseRawGrammar(grammarText, grammarPath) : null,
});
const grammar = await registry.loadGrammar("source.clay");

// ---------------------------------------------------------------------------------------------
// The language's words (docs/language.md).

// Keywords that begin a statement (or a block).
const STATEMENT_KEYWORDS = new Set([
  "import", "let", "param", "solver", "site", "piece", "vertex", "edges", "axis", "polygon", "polyline",
  "mesh", "hole", "state", "stretch", "min", "max", "variants", "merge", "cut", "model", "dock",
  "if", "else",
]);
// Keywords inside a statement, by the statement's first keyword ("=" for `NAME = ...`).
const INNER_KEYWORDS = {
  "site type": ["type", "docks"],
  param: ["in", "choice"],
  site: ["out"],
  piece: ["extends"],
  polygon: ["rigid", "skinned", "fill", "extrude", "above"],
  polyline: ["rigid", "skinned", "width", "fill", "extrude", "above"],
  mesh: ["rigid", "skinned", "fill"],
  state: ["bend", "mirror"],
  stretch: ["from", "to"],
  merge: ["onto", "into", "within"],
  cut: ["into"],
  dock: ["to", "last"],
  "=": ["chain", "x", "along", "at", "rotate"],
};
// Keywords being added to the language alongside this grammar (issue 19's neighbours).
const NEW_KEYWORDS = ["import", "extends", "bend", "mirror", "extrude", "above", "mesh"];
const ALL_KEYWORDS = new Set([...STATEMENT_KEYWORDS, ...Object.values(INNER_KEYWORDS).flat()]);
const BUILTINS = new Set(["sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sqrt", "abs", "min", "max"]);

// ---------------------------------------------------------------------------------------------
// Engine helpers.

/** Tokenizes `text`; per line: its text, tokens {start, end, scopes}, and the scopes left open. */
function tokenize(text) {
  let stack = vsctm.INITIAL;
  return text.split("\n").map((line) => {
    const r = grammar.tokenizeLine(line, stack);
    stack = r.ruleStack;
    // What a following empty line would start inside: the scopes this line leaves open.
    const open = grammar.tokenizeLine("", stack).tokens[0].scopes.slice(1);
    return {
      text: line,
      tokens: r.tokens.map((t) => ({ start: t.startIndex, end: t.endIndex, scopes: t.scopes })),
      open,
    };
  });
}

function scopesAt(lines, line, col) {
  const t = lines[line].tokens.find((t) => t.start <= col && col < t.end);
  assert.ok(t, `no token at ${line + 1}:${col + 1}`);
  return t.scopes;
}

const has = (scopes, prefix) => scopes.some((s) => s === prefix || s.startsWith(prefix + ".") || s.startsWith(prefix));

// ---------------------------------------------------------------------------------------------
// A reference lexer, independent of the TextMate grammar.

/** Tokens {kind, text, line, col} of a clay text; kinds: comment, string, colour, number,
 *  bad-number, name, punct. Block comments nest and may span lines (one token a line). */
function lex(text) {
  const out = [];
  const lines = text.split("\n");
  let depth = 0; // block comment depth carried across lines
  lines.forEach((s, line) => {
    let i = 0;
    const push = (kind, len) => {
      out.push({ kind, text: s.slice(i, i + len), line, col: i });
      i += len;
    };
    while (i < s.length) {
      if (depth > 0) {
        let j = i;
        while (j < s.length && depth > 0) {
          if (s.startsWith("/*", j)) (depth++, (j += 2));
          else if (s.startsWith("*/", j)) (depth--, (j += 2));
          else j++;
        }
        push("comment", j - i);
        continue;
      }
      const rest = s.slice(i);
      let m;
      if (/^\s/.test(rest)) i++;
      else if (rest.startsWith("//")) push("comment", rest.length);
      else if (rest.startsWith("/*")) {
        depth = 1;
        push("comment", 2);
      }
      else if ((m = /^"[^"]*("|$)/.exec(rest))) push("string", m[0].length);
      else if ((m = /^#([0-9A-Fa-f]{8}|[0-9A-Fa-f]{6})(?![A-Za-z0-9_])/.exec(rest))) push("colour", m[0].length);
      else if ((m = /^#\w*/.exec(rest))) push("bad-colour", m[0].length);
      else if (rest.startsWith("..")) push("punct", 2);
      // a `.` before another `.` is a range's `..`, not a decimal point: `1..8`
      else if ((m = /^(\d+(\.(?!\.)\d*)?|\.\d+)([eE][+-]?\d+)?(?!\w|\.(?!\.))/.exec(rest))) push("number", m[0].length);
      else if ((m = /^(\d|\.\d)[\w.]*/.exec(rest))) push("bad-number", m[0].length);
      else if ((m = /^[A-Za-z_]\w*/.exec(rest))) push("name", m[0].length);
      else if (rest.startsWith("->")) push("punct", 2);
      else push("punct", 1);
    }
    out.push({ kind: "eol", text: "", line, col: s.length, inComment: depth > 0 });
  });
  // merge a comment opened by "/*" with its continuation on the same line
  const merged = [];
  for (const t of out) {
    const prev = merged.at(-1);
    if (t.kind === "comment" && prev?.kind === "comment" && prev.line === t.line && prev.col + prev.text.length === t.col) {
      prev.text += t.text;
    } else merged.push({ ...t });
  }
  return merged;
}

/** The significant tokens of a text split into statements: a statement begins at a line's first
 *  token or after `{` / `}`, and ends before the next beginning. */
function statements(tokens) {
  const result = [];
  let cur = null;
  let prev = null;
  for (const t of tokens) {
    if (t.kind === "eol") {
      cur = null;
      continue;
    }
    if (t.kind === "comment") continue;
    const brace = t.kind === "punct" && (t.text === "{" || t.text === "}");
    if (brace) {
      cur = null;
    } else if (cur === null || (prev && prev.kind === "punct" && (prev.text === "{" || prev.text === "}") && prev.line === t.line)) {
      cur = [];
      result.push(cur);
    }
    if (!brace) cur.push(t);
    prev = t;
  }
  return result;
}

/** The statement kind: a key of INNER_KEYWORDS, or null. */
function statementKind(st) {
  const [a, b, c] = st;
  if (a.kind !== "name") return null;
  if (b?.kind === "punct" && b.text === "=") return "=";
  if (!STATEMENT_KEYWORDS.has(a.text) || (b?.kind === "punct" && b.text === "(")) return null;
  if (a.text === "site" && b?.text === "type" && c?.text !== ":") return "site type";
  return a.text;
}

// ---------------------------------------------------------------------------------------------
// The inputs: every example grammar, every ```clay block of docs/language.md, the fixture.

function inputs() {
  const files = [];
  for (const f of readdirSync(path.join(root, "grammars")).sort()) {
    if (f.endsWith(".clay")) files.push({ name: `grammars/${f}`, text: readFileSync(path.join(root, "grammars", f), "utf8"), valid: true });
  }
  const doc = readFileSync(path.join(root, "docs/language.md"), "utf8");
  let n = 0;
  for (const m of doc.matchAll(/^```clay\n([\s\S]*?)^```/gm)) {
    files.push({ name: `docs/language.md block ${++n}`, text: m[1], valid: true });
  }
  files.push({ name: "fixture.clay", text: readFileSync(path.join(here, "fixture.clay"), "utf8"), valid: true });
  return files;
}

const INPUTS = inputs();

test("the inputs are there", () => {
  assert.ok(INPUTS.filter((f) => f.name.startsWith("grammars/")).length >= 5, "grammars/*.clay");
  assert.ok(INPUTS.some((f) => f.name.startsWith("docs/")), "```clay blocks in docs/language.md");
});

test("the grammar names every kw_* rule of dsl/src/grammar.pest and the new keywords", () => {
  const pest = readFileSync(path.join(root, "dsl/src/grammar.pest"), "utf8");
  const words = [...pest.matchAll(/^kw_\w+\s*=\s*@\{\s*"(\w+)"/gm)].map((m) => m[1]);
  assert.ok(words.length >= 30, "found the kw_* rules");
  for (const w of [...words, ...NEW_KEYWORDS]) {
    assert.ok(grammarText.includes(`"keyword.other.${w}.clay"`), `keyword.other.${w}.clay in the grammar`);
    assert.ok(ALL_KEYWORDS.has(w), `the test knows where \`${w}\` goes`);
  }
  const g = JSON.parse(grammarText);
  assert.equal(g.scopeName, "source.clay");
  assert.deepEqual(g.fileTypes, ["clay"]);
});

for (const input of INPUTS) {
  test(`${input.name}`, async (t) => {
    const lines = tokenize(input.text);
    const tokens = lex(input.text);
    const charScopes = (tok, k) => scopesAt(lines, tok.line, tok.col + k);
    const everyChar = (tok, pred, what) => {
      for (let k = 0; k < tok.text.length; k++) {
        const sc = charScopes(tok, k);
        assert.ok(pred(sc), `${input.name}:${tok.line + 1}:${tok.col + k + 1} \`${tok.text}\` ${what}; scopes ${sc.join(" ")}`);
      }
    };

    await t.test("no line leaves a scope open except inside a block comment", () => {
      for (const e of tokens.filter((t) => t.kind === "eol")) {
        const open = lines[e.line].open;
        if (e.inComment) {
          assert.ok(open.length > 0 && open.every((s) => s.startsWith("comment.block")), `${input.name}:${e.line + 1} ends in a block comment; open: ${open.join(" ")}`);
        } else {
          assert.deepEqual(open, [], `${input.name}:${e.line + 1} leaves scopes open`);
        }
      }
    });

    await t.test("comments, strings, colours and numbers", () => {
      for (const tok of tokens) {
        switch (tok.kind) {
          case "comment":
            everyChar(tok, (s) => has(s, "comment"), "is a comment");
            break;
          case "string":
            everyChar(tok, (s) => has(s, "string.quoted.double") && !has(s, "comment"), "is a string");
            break;
          case "colour":
            everyChar(tok, (s) => has(s, "constant.other.color.rgb-value.hex"), "is a colour");
            break;
          case "number":
            everyChar(tok, (s) => has(s, "constant.numeric"), "is a number");
            break;
          case "eol":
            break;
          default:
            everyChar(tok, (s) => !has(s, "comment") && !has(s, "string"), "is not a comment or string");
        }
        if (input.valid && tok.kind !== "eol") everyChar(tok, (s) => !has(s, "invalid"), "is valid");
      }
    });

    await t.test("keywords in their statement positions, and only there", () => {
      for (const st of statements(tokens)) {
        const kind = statementKind(st);
        const [first] = st;
        if (first.kind === "name") {
          const isKw = kind !== null && kind !== "=";
          everyChar(first, (s) => has(s, "keyword.other") === isKw, isKw ? "is a keyword" : "is not a keyword");
        }
        const inner = new Set(INNER_KEYWORDS[kind] ?? []);
        let brackets = 0;
        st.forEach((tok, i) => {
          if (tok.kind === "punct" && tok.text === "[") brackets++;
          if (tok.kind === "punct" && tok.text === "]") brackets--;
          if (i === 0 || tok.kind !== "name") return;
          const next = st[i + 1];
          const call = next?.kind === "punct" && next.text === "(" && next.col === tok.col + tok.text.length;
          if (BUILTINS.has(tok.text) && call) {
            everyChar(tok, (s) => has(s, "support.function.builtin"), "is a built-in function");
          } else if (tok.text === "pi") {
            everyChar(tok, (s) => has(s, "constant.language.pi"), "is the constant pi");
          } else if (inner.has(tok.text) && (brackets === 0 || tok.text === "last")) {
            everyChar(tok, (s) => has(s, "keyword.other"), "is a keyword");
          } else if (!ALL_KEYWORDS.has(tok.text)) {
            everyChar(tok, (s) => !has(s, "keyword"), "is not a keyword");
          }
        });
      }
    });

    await t.test("operators and punctuation", () => {
      for (const tok of tokens.filter((t) => t.kind === "punct")) {
        const want = {
          "+": "keyword.operator", "-": "keyword.operator", "*": "keyword.operator", "/": "keyword.operator",
          "->": "keyword.operator.arrow", "=": "keyword.operator.assignment", "..": "keyword.operator.range",
          ":": "punctuation.separator.colon", ",": "punctuation.separator.comma", ".": "punctuation.accessor",
          "{": "punctuation.section.block", "}": "punctuation.section.block",
          "[": "punctuation.section.brackets", "]": "punctuation.section.brackets",
          "(": "punctuation.section", ")": "punctuation.section",
        }[tok.text];
        assert.ok(want, `${input.name}:${tok.line + 1}:${tok.col + 1} unexpected character \`${tok.text}\``);
        everyChar(tok, (s) => has(s, want), `is ${want}`);
      }
    });
  });
}

// ---------------------------------------------------------------------------------------------
// Hand-written assertions on particular tokens.

/** Asserts that every character of the `nth` occurrence of `needle` on the line of `text` that
 *  contains `lineNeedle` has a scope starting with `scope` (or, with `not`, none). */
function expectScope(text, lineNeedle, needle, scope, { nth = 0, not = false } = {}) {
  const lines = tokenize(text);
  const li = lines.findIndex((l) => l.text.includes(lineNeedle));
  assert.ok(li >= 0, `a line with \`${lineNeedle}\``);
  let col = -1;
  for (let k = 0; k <= nth; k++) col = lines[li].text.indexOf(needle, col + 1);
  assert.ok(col >= 0, `\`${needle}\` on line \`${lines[li].text}\``);
  for (let k = 0; k < needle.length; k++) {
    const sc = scopesAt(lines, li, col + k);
    assert.ok(has(sc, scope) !== not, `\`${needle}\` in \`${lines[li].text.trim()}\`: ${not ? "not " : ""}${scope}; scopes ${sc.join(" ")}`);
  }
}

const wall = readFileSync(path.join(root, "grammars/wall.clay"), "utf8");
const fixture = readFileSync(path.join(here, "fixture.clay"), "utf8");

test("wall.clay: declarations get keyword and entity name scopes", () => {
  expectScope(wall, "piece brick {", "piece", "keyword.other.piece.clay");
  expectScope(wall, "piece brick {", "brick", "entity.name.type.piece.clay");
  expectScope(wall, "piece brick {", "{", "punctuation.section.block.begin.clay");
  expectScope(wall, "site type joint", "site", "keyword.other.site.clay");
  expectScope(wall, "site type joint", "type", "keyword.other.type.clay");
  expectScope(wall, "site type joint", "joint", "entity.name.type.site-type.clay");
  expectScope(wall, "vertex sw (0, 0)", "sw", "entity.name.variable.vertex.clay");
  expectScope(wall, "vertex sw (0, 0)", "(0, 0)", "meta.point.clay");
  expectScope(wall, "site west:", "west", "entity.name.variable.site.clay");
  expectScope(wall, "site west:", "joint", "entity.name.type.site-type.clay");
  expectScope(wall, "site west:", "nw", "variable.other.vertex.clay");
  expectScope(wall, "site west:", "out", "keyword.other.out.clay");
  expectScope(wall, "edges sw-se", "-", "keyword.operator.edge.clay");
  expectScope(wall, "edges sw-se", "se", "variable.other.vertex.clay");
  expectScope(wall, "polygon skinned fill", "#b5651d", "constant.other.color.rgb-value.hex.clay");
  expectScope(wall, "stretch brick from", "brick", "entity.name.type.piece.clay");
  expectScope(wall, "stretch brick from", "west", "variable.other.site.clay");
  expectScope(wall, "stretch brick from", "min", "keyword.other.min.clay");
  expectScope(wall, "wall = chain", "wall", "entity.name.variable.clay");
  expectScope(wall, "wall = chain", "chain", "keyword.other.chain.clay");
  expectScope(wall, "wall = chain", "brick", "entity.name.type.piece.clay");
  expectScope(wall, "wall = chain", "x", "keyword.other.x.clay");
  expectScope(wall, "wall = chain", "at", "keyword.other.at.clay");
  expectScope(wall, "hysteresis = 0.15", "0.15", "constant.numeric.decimal.clay");
});

test("typed parameters and if blocks", () => {
  const line = 'param gate: choice("great", "plain") = "great"';
  expectScope(fixture, line, "choice", "keyword.other.choice.clay");
  expectScope(fixture, line, ":", "punctuation.separator.colon.clay");
  expectScope(fixture, line, '"plain"', "string.quoted.double.clay");
  expectScope(fixture, "param towers: bool = true", "bool", "storage.type.clay");
  expectScope(fixture, "param towers: bool = true", "true", "constant.language.boolean.clay");
  expectScope(fixture, "param bays: int = 6", "int", "storage.type.clay");
  expectScope(fixture, "if towers {", "if", "keyword.other.if.clay");
  expectScope(fixture, "if towers {", "towers", "variable.parameter.clay");
  expectScope(fixture, "} else {", "else", "keyword.other.else.clay");
});

test("the new syntax: import, extends, bend, mirror", () => {
  expectScope(fixture, 'import "corners.clay"', "import", "keyword.other.import.clay");
  expectScope(fixture, 'import "corners.clay"', '"corners.clay"', "string.quoted.double.clay");
  expectScope(fixture, "piece seg extends", "extends", "keyword.other.extends.clay");
  expectScope(fixture, "piece seg extends", "base_seg", "entity.other.inherited-class.piece.clay");
  expectScope(fixture, "piece seg extends", "seg", "entity.name.type.piece.clay");
  expectScope(fixture, "state left bend 90", "left", "entity.name.function.state.clay");
  expectScope(fixture, "state left bend 90", "bend", "keyword.other.bend.clay");
  expectScope(fixture, "state left bend 90", "90", "constant.numeric.decimal.clay");
  expectScope(fixture, "state right mirror left", "mirror", "keyword.other.mirror.clay");
  expectScope(fixture, "state right mirror left", "left", "variable.other.state.clay");
  // an import after a block comment ends, on the same line
  expectScope(fixture, 'out */ import "lib/walls.clay"', "import", "keyword.other.import.clay");
  expectScope(fixture, 'out */ import "lib/walls.clay"', '"lib/walls.clay"', "string.quoted.double.clay");
  expectScope(fixture, 'out */ import "lib/walls.clay"', "out", "comment.block.clay");
});

test("parameters: param, its name, in and the range", () => {
  expectScope(fixture, "param bays = 6 in 2..40", "param", "keyword.other.param.clay");
  expectScope(fixture, "param bays = 6 in 2..40", "bays", "entity.name.constant.clay");
  expectScope(fixture, "param bays = 6 in 2..40", "in", "keyword.other.in.clay");
  expectScope(fixture, "param bays = 6 in 2..40", "..", "keyword.operator.range.clay");
  expectScope(fixture, "param bays = 6 in 2..40", "2", "constant.numeric.decimal.clay", { nth: 0 });
  expectScope(fixture, "param bays = 6 in 2..40", "40", "constant.numeric.decimal.clay");
  expectScope(fixture, "param depth = .5e1 in 0.5..1E+2", "0.5", "constant.numeric.decimal.clay");
  expectScope(fixture, "param depth = .5e1 in 0.5..1E+2", "1E+2", "constant.numeric.decimal.clay");
  expectScope(fixture, "param depth = .5e1 in 0.5..1E+2", "..", "keyword.operator.range.clay");
  expectScope(fixture, "param free = -w in -w..(w + 1)", "(w + 1)", "meta.group.clay");
  expectScope(fixture, "param free = -w in -w..(w + 1)", "w", "variable.other.clay", { nth: 1 });
  expectScope(fixture, "param free = -w in -w..(w + 1)", "in", "keyword.other.in.clay");
  // `in` and `param` are names elsewhere.
  expectScope(fixture, "vertex in (1, 1)", "in", "entity.name.variable.vertex.clay");
  expectScope(fixture, "vertex in (1, 1)", "in", "keyword", { not: true });
  expectScope("piece param {\n}\n", "piece", "param", "entity.name.type.piece.clay");
  expectScope("model {\n    param = p\n}\n", "param =", "param", "entity.name.variable.clay");
});

test("contextual keywords are names outside their positions", () => {
  expectScope(fixture, "vertex site (0, 0)", "site", "entity.name.variable.vertex.clay");
  expectScope(fixture, "vertex site (0, 0)", "site", "keyword", { not: true });
  expectScope(fixture, "site type: plug", "type", "entity.name.variable.site.clay");
  expectScope(fixture, "site type: plug", "plug", "entity.name.type.site-type.clay");
  expectScope(fixture, "edges (1, 0)", "edges", "variable.other.vertex.clay");
  expectScope(fixture, "        site (0, 0)", "site", "variable.other.vertex.clay");
  expectScope(fixture, "dock = base_seg", "dock", "entity.name.variable.clay");
  expectScope(fixture, "dock = base_seg", "base_seg", "entity.name.type.piece.clay");
  expectScope(fixture, "dock dock.east", "dock", "keyword.other.dock.clay");
  expectScope(fixture, "dock dock.east", "dock", "variable.other.instance.clay", { nth: 1 });
  expectScope(fixture, "dock row[last]", "last", "keyword.other.last.clay");
  expectScope(fixture, "dock dock.east to row[0]", "0", "constant.numeric.integer.clay");
  expectScope(fixture, "stretch seg from type to east", "type", "variable.other.site.clay");
});

test("expressions: built-ins, pi, operators, points and groups", () => {
  expectScope(fixture, "let turn", "turn", "entity.name.constant.clay");
  expectScope(fixture, "let turn", "atan2", "support.function.builtin.clay");
  expectScope(fixture, "let turn", "pi", "constant.language.pi.clay");
  expectScope(fixture, "let turn", "/", "keyword.operator.arithmetic.clay");
  expectScope(fixture, "let bay", ".5e1", "constant.numeric.decimal.clay");
  expectScope(fixture, "let bay", "1E+2", "constant.numeric.decimal.clay");
  expectScope(fixture, "let bay", "3.", "constant.numeric.decimal.clay");
  expectScope(fixture, "vertex c (bay / 2", "(bay / 2", "meta.point.clay");
  expectScope(fixture, "vertex c (bay / 2", "sqrt", "support.function.builtin.clay");
  expectScope(fixture, "sin(-(90 + turn))", "(90 + turn)", "meta.group.clay", { nth: 1 });
  expectScope(fixture, "sin(-(90 + turn))", "(90 + turn)", "meta.point.clay", { nth: 1 }); // inside the out point
  expectScope(fixture, "polyline skinned width max", "max", "support.function.builtin.clay");
  expectScope(fixture, "polyline skinned width max", "width", "keyword.other.width.clay");
  expectScope(fixture, "polyline skinned width max", "fill", "keyword.other.fill.clay");
  expectScope(fixture, "polyline skinned width max", "w", "variable.other.clay", { nth: 1 });
  expectScope(fixture, "merge seg.east", "within", "keyword.other.within.clay");
  expectScope(fixture, "merge seg.east", "onto", "keyword.other.onto.clay");
  expectScope(fixture, "merge seg.east", "other_seg", "entity.name.type.piece.clay");
  expectScope(fixture, "cut base_seg.type into seg", "seg", "entity.name.type.piece.clay", { nth: 1 });
  expectScope(fixture, "        seg 0.5,", "seg", "entity.name.type.piece.clay");
  expectScope("let a = min(1, 2)\nstretch s from a to b { min 2 }\n", "stretch", "min", "keyword.other.min.clay");
  expectScope("let a = min(1, 2)\n", "let", "min", "support.function.builtin.clay");
  expectScope("let a = min (1, 2)\n", "let", "min", "support.function.builtin.clay");
  expectScope(fixture, "    max max(", "max", "keyword.other.max.clay");
  expectScope(fixture, "    max max(", "max", "support.function.builtin.clay", { nth: 1 });
  expectScope(fixture, "    max max(", "max", "keyword", { nth: 1, not: true });
  expectScope("let a = max(1, 2)\nstretch s from a to b { max 2 }\n", "stretch", "max", "keyword.other.max.clay");
  expectScope("let a = sinus(1)\n", "let", "sinus", "support.function", { not: true });
  expectScope("let a = pi(1)\n", "let", "pi", "constant.language", { not: true });
});

test("invalid literals", () => {
  expectScope("let a = 2e\n", "let", "2e", "invalid.illegal.numeric.clay");
  expectScope("let a = 1e-\n", "let", "1e", "invalid.illegal.numeric.clay");
  expectScope("let a = 12ab + 1\n", "let", "12ab", "invalid.illegal.numeric.clay");
  expectScope("let a = 1.5.2\n", "let", "1.5.2", "invalid.illegal.numeric.clay");
  expectScope("let a = 1e5\n", "let", "1e5", "constant.numeric.decimal.clay");
  expectScope("let tower_2 = 1\n", "let", "tower_2", "entity.name.constant.clay");
  expectScope("polygon fill #12345 {\n", "polygon", "#12345", "invalid.illegal.colour.clay");
  expectScope("polygon fill #1234567 {\n", "polygon", "#1234567", "invalid.illegal.colour.clay");
  expectScope("polygon fill #abcdefgh {\n", "polygon", "#abcdefgh", "invalid.illegal.colour.clay");
  expectScope("polygon fill #ABCDEF {\n", "polygon", "#ABCDEF", "constant.other.color.rgb-value.hex.clay");
  expectScope("let a = 1;\n", "let", ";", "invalid.illegal.semicolon.clay");
});

test("nested block comments span lines and end where the outermost one ends", () => {
  const text = "/* a /* b\n c */ d\n e */ piece p {\n}\n";
  const lines = tokenize(text);
  assert.deepEqual(lines[0].open, ["comment.block.clay", "comment.block.clay"]);
  assert.deepEqual(lines[1].open, ["comment.block.clay"]);
  assert.deepEqual(lines[2].open, []);
  expectScope(text, " c */ d", "d", "comment.block.clay");
  expectScope(text, " e */ piece", "e", "comment.block.clay");
  expectScope(text, " e */ piece", "piece", "keyword.other.piece.clay");
  expectScope(text, " e */ piece", "piece", "comment", { not: true });
  expectScope("// piece p { /* not a block\npiece q {\n", "piece q", "piece", "keyword.other.piece.clay");
  expectScope("let a = 1 // x /* y\nlet b = 2\n", "let b", "let", "keyword.other.let.clay");
  expectScope("let a = 4 /* c */ / 2\n", "let", "/", "keyword.operator.arithmetic.clay", { nth: 2 });
});

test("a half-typed line does not colour the next one", () => {
  for (const text of ['import "lib.clay\npiece p {\n', "vertex a (1, (2\npiece p {\n", "let a = sqrt(2\npiece p {\n", "site s: t [a, b\npiece p {\n"]) {
    const lines = tokenize(text);
    assert.deepEqual(lines[0].open, [], JSON.stringify(text));
    expectScope(text, "piece p", "piece", "keyword.other.piece.clay");
  }
});

test("editors/vscode contributes this grammar and a language configuration", () => {
  const dir = path.join(root, "editors/vscode");
  const pkg = JSON.parse(readFileSync(path.join(dir, "package.json"), "utf8"));
  const [lang] = pkg.contributes.languages;
  assert.equal(lang.id, "clay");
  assert.deepEqual(lang.extensions, [".clay"]);
  const [g] = pkg.contributes.grammars;
  assert.equal(g.language, "clay");
  assert.equal(g.scopeName, "source.clay");
  // syntaxes/clay.tmLanguage.json is a symbolic link to dsl/syntax's file
  assert.equal(readFileSync(path.join(dir, g.path), "utf8"), grammarText);
  const conf = JSON.parse(readFileSync(path.join(dir, lang.configuration), "utf8"));
  assert.deepEqual(conf.comments, { lineComment: "//", blockComment: ["/*", "*/"] });
  assert.deepEqual(conf.brackets, [["{", "}"], ["[", "]"], ["(", ")"]]);
  const word = new RegExp(`^(?:${conf.wordPattern})$`);
  for (const w of ["tower_2", "0.5", "1e-3", "#b5651d", ".5"]) assert.match(w, word);
  assert.doesNotMatch("a-b", word);
});

test("plist.mjs writes the same grammar as a property list (Sublime Text, TextMate)", async () => {
  const { toPlist } = await import("./plist.mjs");
  const json = JSON.parse(grammarText);
  delete json.$schema;
  const fromPlist = vsctm.parseRawGrammar(toPlist(JSON.parse(grammarText)), "Clay.tmLanguage");
  assert.deepEqual(JSON.parse(JSON.stringify(fromPlist)), json);
});

test("docs/editors.md's scope table names every scope the grammar gives, and no other", () => {
  const given = new Set();
  const walk = (node, top) => {
    if (Array.isArray(node)) return node.forEach((n) => walk(n, false));
    if (node === null || typeof node !== "object") return;
    for (const [key, value] of Object.entries(node)) {
      if (!top && (key === "name" || key === "contentName") && typeof value === "string") given.add(value);
      else walk(value, false);
    }
  };
  walk(JSON.parse(grammarText), true);
  const doc = readFileSync(path.join(root, "docs/editors.md"), "utf8");
  const table = doc.slice(doc.indexOf("| what | scope |")).split("\n\n")[0].split("\n").slice(2);
  assert.ok(table.length > 10, "the table's rows");
  // `keyword.other.WORD.clay` stands for any word, `punctuation.section.*` for any rest.
  const written = table.flatMap((row) => [...row.split(" | ").at(-1).matchAll(/`([a-z][a-z.*A-Z-]*)`/g)].map((m) => m[1]));
  const pattern = (w) => new RegExp(`^${w.replaceAll(".", "\\.").replace("WORD", "[a-z-]+").replace("\\.*", "\\..+")}$`);
  for (const scope of given) {
    assert.ok(written.some((w) => pattern(w).test(scope)), `${scope} is not in docs/editors.md's table`);
  }
  for (const w of written) {
    assert.ok([...given].some((scope) => pattern(w).test(scope)), `the table's ${w} is no scope of the grammar`);
  }
});

test("a second statement on a line is not coloured as one (docs/editors.md)", () => {
  const text = "piece p {\n    vertex a (0, 0) vertex b (1, 0)\n}\n";
  expectScope(text, "vertex a", "vertex", "keyword.other.vertex.clay");
  expectScope(text, "vertex a", "a", "entity.name.variable.vertex.clay", { nth: 0 });
  expectScope(text, "vertex a", "vertex", "variable.other.clay", { nth: 1 });
  expectScope(text, "vertex a", "b", "variable.other.clay");
  expectScope(text, "vertex a", "1", "constant.numeric.decimal.clay");
});
