#!/usr/bin/env bash
# The linker of the wasm32 builds (.cargo/config.toml): rust-lld, without
# the exports of the wasm-streams classes (IntoUnderlyingSource, -Sink,
# -ByteSource) that Leptos's server functions bring. The console has no
# server; exported, their methods and the closures they hand to JavaScript
# stay in the wasm (3.9 KiB gzipped, docs/console.md "Size"), and wasm-opt
# cannot drop them afterwards: the closures' vtables are in the data.
# rustc gives each export as `--export NAME` (or `--export=NAME`), and
# the whole command in a response file (`@FILE`, one argument a line) when
# it is too long for the system.
set -euo pipefail

streams() { [[ ${1,,} == *intounderlying* ]]; }

args=()
while (($#)); do
  case $1 in
    --export)
      if (($# > 1)) && streams "$2"; then shift 2; continue; fi
      args+=("$1" "${2-}")
      shift $(($# > 1 ? 2 : 1))
      continue
      ;;
    --export=*)
      streams "${1#--export=}" || args+=("$1")
      ;;
    @*)
      kept=$(mktemp)
      trap 'rm -f "$kept"' EXIT
      awk 'held { held = 0; if (tolower($0) !~ /intounderlying/) print "--export\n" $0; next }
           $0 == "--export" { held = 1; next }
           tolower($0) ~ /^--export=.*intounderlying/ { next }
           { print }' "${1#@}" >"$kept"
      args+=("@$kept")
      ;;
    *) args+=("$1") ;;
  esac
  shift
done
if ((${#args[@]} > 0)); then rust-lld "${args[@]}"; else rust-lld; fi
