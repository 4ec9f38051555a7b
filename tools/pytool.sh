#!/bin/sh
# pytool.sh TOOL [ARG...] - run tools/TOOL.py with the project's Python (build/venv),
# which has the packages the tools import (numpy, pyserial, Pillow; requirements.txt)
# and the system python3 may not. bin/TOOL calls this, from any folder.
root=$(cd "$(dirname "$(readlink -f "$0")")/.." && pwd)
py="$root/build/venv/bin/python"
tool=$1
shift
if [ ! -x "$py" ]; then
  echo "bin/$tool: $py is missing: run 'make deps' in $root first" >&2
  exit 127
fi
exec "$py" "$root/tools/$tool.py" "$@"
