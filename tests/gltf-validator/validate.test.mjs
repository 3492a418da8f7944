// Every example grammar, initial and after its script, exported by `clayc export` to .glb and
// .gltf, must have 0 errors and 0 warnings in the Khronos glTF validator (issue 20).
// CLAYC names the binary (default: the debug build of the workspace).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import validator from 'gltf-validator';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
const target = process.env.CARGO_TARGET_DIR ?? path.join(root, 'target');
const clayc = process.env.CLAYC ?? path.join(target, 'debug', 'clayc');
const out = fs.mkdtempSync(path.join(os.tmpdir(), 'clay-gltf-'));
const grammars = fs.readdirSync(path.join(root, 'grammars')).filter((f) => f.endsWith('.clay'));

test('there are examples to export', () => {
  assert.ok(grammars.length >= 5, `only ${grammars.length} grammars`);
  assert.ok(fs.existsSync(clayc), `no clayc at ${clayc}: build it first (cargo build)`);
});

for (const g of grammars) {
  const stem = g.replace(/\.clay$/, '');
  const script = path.join(root, 'grammars', `${stem}.script.json`);
  const runs = [['initial', []]];
  if (fs.existsSync(script)) runs.push(['sculpted', ['--script', script]]);
  for (const [when, extra] of runs) {
    for (const ext of ['glb', 'gltf']) {
      test(`${g} ${when} .${ext} validates clean`, async () => {
        const file = path.join(out, `${stem}-${when}.${ext}`);
        execFileSync(clayc, ['export', path.join(root, 'grammars', g), ...extra, '-o', file], {
          stdio: ['ignore', 'ignore', 'pipe'],
        });
        const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
          uri: file,
        });
        const issues = report.issues.messages
          .filter((m) => m.severity <= 1)
          .map((m) => `${m.code} ${m.message} ${m.pointer ?? ''}`);
        assert.equal(report.issues.numErrors, 0, issues.join('\n'));
        assert.equal(report.issues.numWarnings, 0, issues.join('\n'));
        assert.ok(report.info.drawCallCount > 0, 'something is drawn');
      });
    }
  }
}
