// Prints dsl/syntax/clay.tmLanguage.json as a TextMate property list (the XML `.tmLanguage`
// format that Sublime Text and TextMate 2 read):
//   node dsl/syntax/test/plist.mjs > Clay.tmLanguage
import { readFileSync } from "node:fs";
import { resolve } from "node:path";
import { fileURLToPath } from "node:url";

const esc = (s) => s.replace(/&/g, "&amp;").replace(/</g, "&lt;").replace(/>/g, "&gt;");

export function plist(value, indent = "") {
  const inner = indent + "  ";
  if (typeof value === "string") return `${indent}<string>${esc(value)}</string>`;
  if (Array.isArray(value)) {
    return [`${indent}<array>`, ...value.map((v) => plist(v, inner)), `${indent}</array>`].join("\n");
  }
  if (value && typeof value === "object") {
    const entries = Object.entries(value)
      .filter(([k]) => k !== "$schema")
      .flatMap(([k, v]) => [`${inner}<key>${esc(k)}</key>`, plist(v, inner)]);
    return [`${indent}<dict>`, ...entries, `${indent}</dict>`].join("\n");
  }
  throw new Error(`no plist form for ${JSON.stringify(value)}`);
}

export function toPlist(grammar) {
  return [
    '<?xml version="1.0" encoding="UTF-8"?>',
    '<!DOCTYPE plist PUBLIC "-//Apple//DTD PLIST 1.0//EN" "http://www.apple.com/DTDs/PropertyList-1.0.dtd">',
    '<plist version="1.0">',
    plist(grammar),
    "</plist>",
    "",
  ].join("\n");
}

if (process.argv[1] && resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  const file = new URL("../clay.tmLanguage.json", import.meta.url);
  process.stdout.write(toPlist(JSON.parse(readFileSync(file, "utf8"))));
}
