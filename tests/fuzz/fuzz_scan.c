/* fuzz_scan.c - libFuzzer target for the SDL scanner (parser/sdl_scan.h).
 *
 * Scans the input (an exact-size copy, so a read past `len` is an ASan
 * error) to the end and checks the scanner's own promises: every token lies
 * inside the buffer, locations only move forward, the scan ends, and seeking
 * back to a saved position replays exactly the same tokens. Strings are
 * unescaped into buffers of several sizes, tokens described for messages. */
#include <stdio.h>
#include "fuzz_sdl.h"
#include "sdl_scan.h"

#define MAX_TOKENS 100000

static void check_token(const sdl_token *t, const char *buf, size_t size)
{
    if (t->kind == TOK_EOF || t->kind == TOK_ERROR) return;
    FUZZ_CHECK(t->text >= buf && t->len >= 0 && (size_t)(t->text - buf) + (size_t)t->len <= size);
    if (t->kind == TOK_STRING) {
        char small[4], big[512];
        size_t n = sdl_scan_unescape(t, small, sizeof small);
        FUZZ_CHECK(n < sizeof small && small[n] == 0);
        n = sdl_scan_unescape(t, big, sizeof big);
        FUZZ_CHECK(n < sizeof big);
        size_t cap = (size_t)t->len * 3 + 1; /* what the parser allocates */
        char *all = malloc(cap);
        if (all) {
            n = sdl_scan_unescape(t, all, cap);
            FUZZ_CHECK(n < cap);
            free(all);
        }
    }
    if (t->kind == TOK_KEYWORD) FUZZ_CHECK(t->kw > KW_NONE && t->kw < SDL_KW_LIMIT && sdl_kw_text(t->kw)[0]);
    char desc[96];
    sdl_tok_describe(t, desc, sizeof desc);
    FUZZ_CHECK(strlen(desc) < sizeof desc);
    FUZZ_CHECK(sdl_tok_kind_text(t->kind)[0]);
}

static int same_token(const sdl_token *a, const sdl_token *b)
{
    return a->kind == b->kind && a->text == b->text && a->len == b->len && a->loc.line == b->loc.line &&
           a->loc.col == b->loc.col && (a->kind != TOK_NUMBER || memcmp(&a->num, &b->num, sizeof a->num) == 0);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > FUZZ_MAX_INPUT) return 0;
    char *buf = malloc(size ? size : 1);
    if (!buf) return 0;
    if (size) memcpy(buf, data, size);

    sdl_scanner s;
    sdl_scan_init(&s, "fuzz.pov", buf, size);
    sdl_scan_pos mark = sdl_scan_tell(&s);
    sdl_token replay[8];
    int nreplay = 0, marked = 0;
    int last_line = 1, last_col = 0;
    size_t last_pos = 0;
    for (int i = 0; i < MAX_TOKENS; i++) {
        if (i == 3) {
            mark = sdl_scan_tell(&s);
            marked = 1;
        }
        sdl_token t = sdl_scan_next(&s);
        check_token(&t, buf, size);
        if (marked && nreplay < 8) replay[nreplay++] = t;
        /* Positions move forward: the scan always ends. */
        size_t pos = sdl_scan_tell(&s).pos;
        FUZZ_CHECK(pos <= size);
        FUZZ_CHECK(pos > last_pos || t.kind == TOK_EOF || (t.kind == TOK_ERROR && pos >= last_pos));
        FUZZ_CHECK(t.loc.line > last_line || (t.loc.line == last_line && t.loc.col >= last_col) || t.kind == TOK_ERROR);
        if (t.kind != TOK_ERROR) {
            last_line = t.loc.line;
            last_col = t.loc.col;
        }
        last_pos = pos;
        if (t.kind == TOK_EOF) break;
        if (t.kind == TOK_ERROR) {
            FUZZ_CHECK(s.err[0]);
            if (pos == size) break;
        }
    }
    if (marked) {
        sdl_scan_seek(&s, mark);
        for (int i = 0; i < nreplay; i++) {
            sdl_token t = sdl_scan_next(&s);
            FUZZ_CHECK(same_token(&t, &replay[i]));
        }
    }
    free(buf);
    return 0;
}
