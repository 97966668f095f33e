/* sdl_scan.h - POV-Ray SDL scanner: text -> tokens with source locations.
 *
 * Handles // and nested block comments, strings with escapes, numbers,
 * identifiers and keywords (sdl_keywords.h) and punctuation. It knows nothing
 * about directives: '#' is a token like any other. A scanner reads one
 * buffer; the caller keeps the buffer alive and can save/restore positions
 * (for #while loops and macro bodies). */
#ifndef PT_SDL_SCAN_H
#define PT_SDL_SCAN_H
#include <stddef.h>
#include "diag.h"
#include "sdl_keywords.h"

typedef enum {
    TOK_EOF = 0,
    TOK_ERROR,    /* lexical error; the scanner's `err` says why */
    TOK_NUMBER,
    TOK_STRING,   /* text/len: the body between the quotes, escapes not decoded */
    TOK_IDENT,
    TOK_KEYWORD,
    TOK_LBRACE, TOK_RBRACE, TOK_LPAREN, TOK_RPAREN, TOK_LBRACKET, TOK_RBRACKET,
    TOK_LT, TOK_GT, TOK_LE, TOK_GE, TOK_EQ, TOK_NE,
    TOK_COMMA, TOK_SEMI, TOK_PLUS, TOK_MINUS, TOK_STAR, TOK_SLASH, TOK_DOT,
    TOK_QUESTION, TOK_COLON, TOK_BANG, TOK_AMP, TOK_BAR, TOK_HASH
} sdl_tok_kind;

typedef struct {
    sdl_tok_kind kind;
    sdl_kw kw;         /* TOK_KEYWORD */
    src_loc loc;
    const char *text;  /* into the scanned buffer */
    int len;
    double num;        /* TOK_NUMBER */
} sdl_token;

typedef struct {
    size_t pos;
    int line, col;
} sdl_scan_pos;

typedef struct {
    const char *file;  /* interned name used in locations */
    const char *text;
    size_t len;
    sdl_scan_pos at;
    char err[160];
} sdl_scanner;

void sdl_scan_init(sdl_scanner *s, const char *file, const char *text, size_t len);
sdl_token sdl_scan_next(sdl_scanner *s);
sdl_scan_pos sdl_scan_tell(const sdl_scanner *s);
void sdl_scan_seek(sdl_scanner *s, sdl_scan_pos p);

/* Decode a TOK_STRING's escapes (\n \t \\ \" ...) into out (NUL-terminated,
 * truncated to cap-1 bytes). Returns the decoded length. */
size_t sdl_scan_unescape(const sdl_token *t, char *out, size_t cap);
/* Short human description of a token for messages: "'sphere'", "number 1.5",
 * "end of file". */
const char *sdl_tok_describe(const sdl_token *t, char *buf, size_t cap);
/* Spelling of a punctuation kind ("{"), or a name for the others. */
const char *sdl_tok_kind_text(sdl_tok_kind k);

#endif
