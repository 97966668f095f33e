#!/bin/sh
# test_docs.sh ROOT - the manual states what is true now and stays inside
# the repository. Over README.md and docs/*.md:
#  - every relative link resolves to a file or folder in the repository
#    (web links are not followed);
#  - no dated entry, clock time, commit hash, issue number, session or
#    work-period name (git keeps the history);
#  - every image a page shows names, in its paragraph, the bench/ command
#    that makes it.
# The sources' comments (code, build files, scripts, scenes) carry no date,
# clock time, issue, session or work-period name either.
# Also: the user guide names every display, view and look of the shipped
# OCIO config, and `partray render --help` (app/cli.c's cli_render_help)
# lists every GNU-style option app/cli.c parses.
# Prints each offence as FILE:LINE: what; exit 1 when there is one.
root=${1:-.}
cd "$root" || exit 2
files=$(ls README.md docs/*.md 2>/dev/null)
bad=0
say() { echo "$1"; bad=1; }

for f in $files; do
    dir=$(dirname "$f")
    # links: [text](target) and ![alt](target), target up to ')' or a space
    grep -n -o '\]([^) ]*' "$f" | while IFS= read -r m; do
        line=${m%%:*}
        t=${m#*](}
        t=${t%%#*}
        case "$t" in
        ''|http://*|https://*|mailto:*) continue ;;
        esac
        p="$dir/$t"
        if [ ! -e "$p" ]; then
            echo "$f:$line: link '$t' does not resolve"
            continue
        fi
        real=$(cd "$(dirname "$p")" 2>/dev/null && pwd -P)
        case "$real/" in
        "$(pwd -P)"/*) ;;
        *) echo "$f:$line: link '$t' leaves the repository" ;;
        esac
    done
done > /tmp/test_docs.$$ 2>&1
if [ -s /tmp/test_docs.$$ ]; then cat /tmp/test_docs.$$; bad=1; fi
rm -f /tmp/test_docs.$$

# history: dates, clock times, hashes, issue numbers, sessions, periods
pat_date='(19|20)[0-9]{2}-[01][0-9]-[0-3][0-9]|(^|[^0-9.])[0-9]{1,2} (Jan|Feb|Mar|Apr|Jun|Jul|Aug|Sep|Oct|Nov|Dec)([^a-z]|$)|[0-9]{1,2} (Jan|Feb|Mar|Apr|May|Jun|Jul|Aug|Sep|Oct|Nov|Dec)[a-z]* (19|20)[0-9]{2}|(Jan|Feb|Mar|Apr|May|Jun|Jul|Aug|Sep|Oct|Nov|Dec)[a-z]* [0-9]{1,2},? (19|20)[0-9]{2}'
pat_time='[0-2][0-9]:[0-5][0-9](-[0-2][0-9]:[0-5][0-9])? UTC'
pat_issue='[Ii]ssues?[ -]#?[0-9]+|[Ss]ession [0-9]+|[Ww]ork period|\(branch [a-z0-9_-]+'
for f in $files; do
    grep -n -E "$pat_date" "$f" | sed "s|^|$f:|; s|$| <- a date|"
    grep -n -E "$pat_time" "$f" | sed "s|^|$f:|; s|$| <- a clock time|"
    grep -n -E "$pat_issue" "$f" | sed "s|^|$f:|; s|$| <- an issue, session, period or branch|"
    # a commit hash: 7 to 40 hex digits with both a digit and a letter, a word of its own
    grep -n -o -E '(^|[^0-9A-Za-z_x])[0-9a-f]{7,40}([^0-9A-Za-z_]|$)' "$f" |
        grep -E ':.*[0-9].*' | grep -E ':.*[a-f]' | grep -v -E ':[^0-9a-f]*[0-9]{7,40}[^0-9a-f]*$' |
        sed "s|^|$f:|; s|$| <- a commit hash?|"
done > /tmp/test_docs.$$
if [ -s /tmp/test_docs.$$ ]; then cat /tmp/test_docs.$$; bad=1; fi
rm -f /tmp/test_docs.$$

# the same dates, clock times and issue, session or period names in the
# sources' comments (code, build files, scripts, scenes): comments state
# invariants and reasons. An upstream project's issue ("OpenEXR issue
# #2306") and POV-Ray's datetime epochs (2000-01-01, 1970-01-01) are facts
# of the world, not history.
srcs=$(git ls-files '*.c' '*.h' '*.cl' '*.cpp' '*.sh' '*.py' '*CMakeLists.txt' '*.cmake' '*.pov' '*.inc' '*.ini' 2>/dev/null ||
    find . -name '*.[ch]' -o -name '*.cl' -o -name '*.cpp' -o -name '*.sh' -o -name '*.pov' -o -name CMakeLists.txt)
for f in $srcs; do
    [ "$f" = tests/test_docs.sh ] && continue
    grep -n -E "$pat_date|$pat_time|$pat_issue" "$f" | grep -v -E 'OpenEXR issue #|(2000|1970)-01-01' |
        sed "s|^|$f:|; s|$| <- a date, clock time, issue, session or period in a comment|"
done > /tmp/test_docs.$$
if [ -s /tmp/test_docs.$$ ]; then cat /tmp/test_docs.$$; bad=1; fi
rm -f /tmp/test_docs.$$

# images name their bench command in the same paragraph
for f in $files; do
    awk -v F="$f" '
        /^[[:space:]]*$/ { if (img && !bench) printf "%s:%d: image without the bench/ command that makes it\n", F, at; img = bench = 0; next }
        /!\[[^]]*\]\(/ { if (!img) at = NR; img = 1 }
        /bench\// { bench = 1 }
        END { if (img && !bench) printf "%s:%d: image without the bench/ command that makes it\n", F, at }'  "$f"
done > /tmp/test_docs.$$
if [ -s /tmp/test_docs.$$ ]; then cat /tmp/test_docs.$$; bad=1; fi
rm -f /tmp/test_docs.$$

# the user guide names every display, view and look the shipped OCIO config has
if [ -f io/ocio/config.ocio ] && [ -f docs/guide.md ]; then
    sed -n -e 's/.*!<View> {name: \([^,]*\),.*/\1/p' -e '/!<Look>/{n;s/^ *name: //p;}' -e '/^displays:/,/^[a-z]/s/^  \([A-Za-z0-9.]*\):$/\1/p' \
        io/ocio/config.ocio | sort -u | while IFS= read -r n; do
        grep -q -F "\`$n\`" docs/guide.md || echo "docs/guide.md: the OCIO name '$n' (io/ocio/config.ocio) is not listed"
    done > /tmp/test_docs.$$
    if [ -s /tmp/test_docs.$$ ]; then cat /tmp/test_docs.$$; bad=1; fi
    rm -f /tmp/test_docs.$$
fi

# `partray render --help` lists every GNU-style option app/cli.c parses
if [ -f app/cli.c ]; then
    help=$(sed -n '/^const char cli_render_help/,/^;/p' app/cli.c)
    grep -o 'strcmp(a, "--[a-z0-9-]*")' app/cli.c | sed 's/.*"\(--[a-z0-9-]*\)".*/\1/' | sort -u | while IFS= read -r o; do
        printf '%s\n' "$help" | grep -q -e "$o" || echo "app/cli.c: option $o is missing from cli_render_help"
    done > /tmp/test_docs.$$
    if [ -s /tmp/test_docs.$$ ]; then cat /tmp/test_docs.$$; bad=1; fi
    rm -f /tmp/test_docs.$$
fi

[ $bad = 0 ] && echo "docs: links resolve; no dates, hashes, issue numbers or sessions"
exit $bad
