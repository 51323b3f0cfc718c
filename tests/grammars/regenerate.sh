#!/bin/sh
# Regenerate the Python parser in krl/ from the vendored, unmodified krl/krl.g4 (see README.md):
# antlr-ng 1.0.10 (npm, the TypeScript port of the ANTLR 4 tool; needs Node.js >= 20 and npx),
# for antlr4-python3-runtime 4.13.2. Only the three modules are kept: the .interp and .tokens
# files it also writes are not read at run time.
set -eu
cd "$(dirname "$0")"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
npx --yes antlr-ng@1.0.10 -Dlanguage=Python3 -o "$out" krl/krl.g4
cp "$out/krlLexer.py" "$out/krlParser.py" "$out/krlListener.py" krl/
