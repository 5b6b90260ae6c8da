#!/bin/sh
# Every global symbol defined in libpartix (static and shared) carries the px_
# prefix, so partix never collides with the programs that link it.
#   check_symbols.sh libpartix.a libpartix.so
set -u
status=0
bad=$(nm -g --defined-only "$1" 2>/dev/null | awk 'NF == 3 && $2 ~ /[A-Z]/ {print $3}' | grep -v '^px_' | sort -u)
if [ -n "$bad" ]; then
  echo "symbols without the px_ prefix in $1:"; echo "$bad"; status=1
fi
bad=$(nm -D --defined-only "$2" 2>/dev/null | awk 'NF == 3 && $2 ~ /[A-Z]/ {print $3}' | grep -v '^px_' | sort -u)
if [ -n "$bad" ]; then
  echo "exported symbols without the px_ prefix in $2:"; echo "$bad"; status=1
fi
count=$(nm -D --defined-only "$2" | awk 'NF == 3 && $2 == "T"' | wc -l)
if [ "$count" -lt 10 ]; then
  echo "only $count functions exported from $2: visibility broken?"; status=1
fi
# The library never ends the process: no exit/abort, and no assert() (which aborts).
bad=$(nm -u "$1" 2>/dev/null | awk '{print $NF}' | grep -E '^(exit|_exit|_Exit|quick_exit|abort|__assert_fail)$' | sort -u)
if [ -n "$bad" ]; then
  echo "libpartix calls functions that end the process: $bad"; status=1
fi
[ $status -eq 0 ] && echo "all symbols carry the px_ prefix ($count exported functions)"
exit $status
