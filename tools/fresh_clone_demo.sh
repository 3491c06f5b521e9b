#!/bin/sh
# `make demo` as on a fresh machine's clone: clone this repository at REV into DIR, empty the
# numba cache of that checkout (clearbench.numba_cache_dir names it after the checkout's path),
# then `make demo` there (the virtual environment made, the kernels compiled cold), its output
# appended to LOG. Time two revisions side by side with farm-bench:
#
#   farm-bench -n 1 --warmup 0 --timeout 3000 \
#     --vs "tools/fresh_clone_demo.sh /tmp/demo-base BASE_REV /tmp/demo-base.log" \
#     -- tools/fresh_clone_demo.sh /tmp/demo-this HEAD /tmp/demo-this.log
set -e
dir=$1 rev=$2 log=$3
repository=$(git -C "$(dirname "$0")" rev-parse --show-toplevel)
rev=$(git -C "$repository" rev-parse --verify "$rev^{commit}")
rm -rf "$dir"
git clone -q "$repository" "$dir"
cd "$dir"
git checkout -q "$rev"
cache=$(python3 -c "import hashlib, sys; print(hashlib.sha1(sys.argv[1].encode()).hexdigest()[:12])" "$(pwd -P)")
rm -rf "${XDG_CACHE_HOME:-$HOME/.cache}/clearbench-numba-checkouts/$cache"
echo "=== $(date -u) $rev" >> "$log"
exec make demo >> "$log" 2>&1
