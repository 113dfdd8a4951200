#!/usr/bin/env bash
# The house's function-length bar (STYLE.md 6, issue #21): lists every production function (all
# tracked C++ outside tests/) longer than MAX lines, longest first, as "LINES FILE FUNCTION", and
# exits 1 when there is one. A function's length is from its signature's line to its closing brace,
# as universal-ctags reports them (`end:`); a lambda counts on its own (`__anon...`).
#   bash scripts/long_functions.sh          # MAX = 40
#   bash scripts/long_functions.sh 60 agent/  # another bar, one folder
# ctest runs it as `HouseFunctionLength`. Needs git and universal-ctags (scripts/setup.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
max=${1:-40}
prefix=${2:-}
if ! ctags --version 2>/dev/null | grep -q 'Universal Ctags'; then
  echo "long_functions.sh: universal-ctags is not installed (bash scripts/setup.sh installs it)" >&2
  exit 2
fi
long=$(git ls-files -- '*.cpp' '*.hpp' | grep -v '^tests/' | grep "^${prefix}" |
  xargs ctags --kinds-c++=f --fields=+ne --output-format=u-ctags -f - 2>/dev/null |
  awk -F'\t' '{n = ""; e = ""
               for (i = 4; i <= NF; i++) { if ($i ~ /^line:/) n = substr($i, 6); if ($i ~ /^end:/) e = substr($i, 5) }
               if (e != "") print e - n + 1, $2, $1}' |
  sort -rn | awk -v m="$max" '$1 > m')
if [ -n "$long" ]; then
  echo "long_functions.sh: $(echo "$long" | wc -l) production function(s) over $max lines:"
  echo "$long"
  exit 1
fi
echo "long_functions.sh: no production function over $max lines"
