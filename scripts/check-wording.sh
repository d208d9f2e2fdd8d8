#!/usr/bin/env bash
# The repository speaks of the product, not of the process that made it: no tracked text may
# name a tracker item ("issue 21", "issues #3") or a numbered round of development ("session
# 15", "sessions 32 and 33"). Run by scripts/test-all.sh; fails with every line it finds.
#
# Usage: scripts/check-wording.sh [REPO_DIR]     (default: this repository)
#        scripts/check-wording.sh --self-test     (shows that the check catches what it must)
set -euo pipefail

# Kept in one variable, written so that this file does not match itself.
pattern='\b([Ii]ssue|[Ss]ession)s?[[:space:]]+#?[0-9]+'

check() {
  local dir=$1 hits
  # This file names the forms it refuses (its examples and self-test), so it is left out.
  hits=$(git -C "$dir" grep -nIE "$pattern" -- . ':!scripts/check-wording.sh' || true)
  if [ -n "$hits" ]; then
    echo "$hits" >&2
    echo "check-wording: $(grep -c . <<<"$hits") tracked lines name a tracker item or a numbered" \
      "round of development; say what the product does instead" >&2
    return 1
  fi
}

if [ "${1:-}" = "--self-test" ]; then
  tmp=$(mktemp -d)
  trap 'rm -rf "$tmp"' EXIT
  git -C "$tmp" init -q
  printf 'A tissue 3 cm wide, two sessions of the link, issue-free.\n' >"$tmp/ok.md"
  git -C "$tmp" add ok.md
  check "$tmp" || { echo "check-wording: self-test: legitimate text was flagged" >&2; exit 1; }
  for bad in 'closed loop (issue 21)' 'Session 15: the exploring collection' \
    'sessions 32 and 33 changed' 'see issue #4' 'Issues 3'; do
    printf '%s\n' "$bad" >"$tmp/bad.rs"
    git -C "$tmp" add bad.rs
    if check "$tmp" 2>/dev/null; then
      echo "check-wording: self-test: '$bad' was not caught" >&2
      exit 1
    fi
  done
  echo "check-wording: self-test passed"
  exit 0
fi

check "${1:-$(cd "$(dirname "$0")/.." && pwd)}"
echo "check-wording: no tracked line names a tracker item or a numbered round of development"
