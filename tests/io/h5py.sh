#!/bin/sh
# h5py alone reads the files seixo writes (docs/file-format.md).
#   h5py.sh SEIXO SOURCE_DIR
# Skipped (exit 77) when no python3 with h5py is installed
# (Debian: apt-get install python3-h5py; scripts/setup --test installs it).
set -eu
seixo=$1 src=$2
py=
for p in python3 /usr/bin/python3; do
    if command -v "$p" > /dev/null 2>&1 && "$p" -c "import h5py" 2> /dev/null; then
        py=$p
        break
    fi
done
[ -n "$py" ] || { echo "no python3 with h5py: skipped"; exit 77; }
dir=$(mktemp -d "${TMPDIR:-/tmp}/seixo-h5py-XXXXXX")
trap 'rm -rf "$dir"' EXIT
"$seixo" "$src/h5py_files.lua" "$dir"
"$py" "$src/h5py_check.py" "$dir"
