#!/bin/sh
# resume_identity.sh PARTIX CASE N1 N2 N3 [OPTION...]
#
# A run interrupted twice and resumed leaves the same run folder as an
# uninterrupted one, file by file: CASE is run to step N3 in one go, and
# again to N1, resumed to N2 from another directory, and resumed to N3 from a
# third (OPTIONs, e.g. --set key=value, go to both first runs). Every file
# of the two folders must be byte-identical, except
#  - run.log (it holds wall-clock times), which must exist;
#  - summary.json, compared without its "wall_time_s" line;
#  - checkpoint.pxc, compared without its creation time and the CRCs that
#    cover it (docs/checkpoint-format.md: header bytes 48..55, the header CRC,
#    the file CRC).
# Exit 0 when identical; the differing files are listed otherwise.
set -u
partix=$1 case=$2 n1=$3 n2=$4 n3=$5
shift 5
case "$case" in /*) ;; *) case=$(pwd)/$case ;; esac
case "$partix" in /*) ;; *) partix=$(pwd)/$partix ;; esac
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/whole" "$tmp/parts" "$tmp/elsewhere/deeper"

fail() { echo "resume_identity: $*"; exit 1; }

(cd "$tmp/whole" && "$partix" -q run "$case" --out out --steps "$n3" --no-progress "$@") ||
  fail "the uninterrupted run failed"
(cd "$tmp/parts" && "$partix" -q run "$case" --out out --steps "$n1" --no-progress "$@") ||
  fail "the first part failed"
(cd "$tmp/elsewhere" && "$partix" -q resume ../parts/out/checkpoint.pxc --steps "$n2" \
  --no-progress) || fail "the first resume failed"
(cd "$tmp/elsewhere/deeper" && "$partix" -q resume "$tmp/parts/out/checkpoint.pxc" \
  --steps "$n3" --no-progress) || fail "the second resume failed"

python3 "$(dirname "$0")/compare_runs.py" "$tmp/whole/out" "$tmp/parts/out" || exit 1
