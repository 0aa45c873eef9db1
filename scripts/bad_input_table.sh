#!/usr/bin/env bash
# docs/BAD_INPUT.md from the tests themselves: runs the end-to-end tests with
# GRANMEM_BAD_INPUT_LOG set, so that every input they refuse (expect_clean_failure in
# tests/app/run_granmem.hpp: one line on stderr, a non-zero exit, nothing written or left
# behind) is logged with its command and message, and writes the table.
# Usage: scripts/bad_input_table.sh [build folder, default build]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
log=$(mktemp)
trap 'rm -f "$log"' EXIT
GRANMEM_BAD_INPUT_LOG=$log "$build/tests/granmem_app_tests" > /dev/null
/usr/bin/python3 - "$log" docs/BAD_INPUT.md "$PWD" <<'PY'
import sys
rows = [line.rstrip("\n").split("\t") for line in open(sys.argv[1]) if line.strip()]
repo = sys.argv[3]
def cell(text):
    text = text.replace(repo + "/", "")  # the checkout's path, whatever it is
    return "`" + text.replace("|", "\\|").replace("`", "'") + "`"
by_command = {}
for test, command, code, message in rows:
    words, word = command.split()[1:], "(no command)"
    while words:  # the command is the first word that is no global option or its value
        if words[0] == "--config":
            words = words[2:]
        elif words[0].startswith("-"):
            words = words[1:]
        else:
            word = words[0]
            break
    by_command.setdefault(word, []).append((test, command, code, message))
out = ["# Bad input: what granmem refuses, and how",
       "",
       "Every row is an input a test in `tests/app/` gives the command line and the one line",
       "granmem answers with: a non-zero exit status (2 for a usage error, 1 for any other),",
       "nothing on stdout, one line on stderr, no file written, changed or left behind",
       "(`expect_clean_failure` in `tests/app/run_granmem.hpp` asserts all of it). Files named",
       "in a command are the test's own (a good table, a run, a damaged file); `GranmemTest`",
       "fixtures make them. Regenerate after changing a test or a message:",
       "",
       "```sh",
       "scripts/bad_input_table.sh        # runs build/tests/granmem_app_tests, writes this file",
       "```",
       "",
       f"{len(rows)} refused inputs across {len(by_command)} commands.",
       ""]
for word in sorted(by_command):
    out += [f"## `{word}`", "", "| test | command | exit | message |", "|---|---|---|---|"]
    for test, command, code, message in by_command[word]:
        message = message.removeprefix("granmem: error: ")
        if len(message) > 240:
            message = message[:240] + "..."
        out.append(f"| {test} | {cell(command)} | {code} | {cell(message)} |")
    out.append("")
open(sys.argv[2], "w").write("\n".join(out))
print(f"wrote {sys.argv[2]}: {len(rows)} refused inputs")
PY
