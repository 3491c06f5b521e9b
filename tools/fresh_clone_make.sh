#!/bin/sh
# A make target (default `demo`) as on a fresh machine's clone: clone this repository at REV
# into DIR, empty the numba cache of that checkout (clearbench.numba_cache_dir names it after
# the checkout's path), then `make TARGET` there (the virtual environment made, the kernels
# compiled cold), its output appended to LOG. Time two revisions side by side, in turn:
#
#   python3 tools/time_in_turn.py -n 1 \
#     --vs "tools/fresh_clone_make.sh /tmp/base BASE_REV /tmp/base.log test" \
#     -- tools/fresh_clone_make.sh /tmp/this HEAD /tmp/this.log test
set -e
dir=$1 rev=$2 log=$3 target=${4:-demo}
repository=$(git -C "$(dirname "$0")" rev-parse --show-toplevel)
rev=$(git -C "$repository" rev-parse --verify "$rev^{commit}")
rm -rf "$dir"
git clone -q "$repository" "$dir"
cd "$dir"
git checkout -q "$rev"
cache=$(python3 -c "import hashlib, sys; print(hashlib.sha1(sys.argv[1].encode()).hexdigest()[:12])" "$(pwd -P)")
rm -rf "${XDG_CACHE_HOME:-$HOME/.cache}/clearbench-numba-checkouts/$cache"
echo "=== $(date -u) $rev make $target" >> "$log"
exec make "$target" >> "$log" 2>&1
