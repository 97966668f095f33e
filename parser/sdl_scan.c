/* sdl_scan.c - POV-Ray SDL scanner. */
#include "sdl_scan.h"
#include <assert.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const kw_texts[] = {
    "",
#define SDL_KW_TEXT(id, text) text,
    SDL_KEYWORDS(SDL_KW_TEXT)
#undef SDL_KW_TEXT
};

const char *sdl_kw_text(sdl_kw k)
{
    return (k > KW_NONE && k < SDL_KW_LIMIT) ? kw_texts[k] : "";
}

static const unsigned char kw_lens[] = {
    0,
#define SDL_KW_LEN(id, text) (unsigned char)(sizeof(text) - 1),
    SDL_KEYWORDS(SDL_KW_LEN)
#undef SDL_KW_LEN
};

/* Compare the word s[0..n) with keyword k, strcmp order. */
static int word_cmp(const char *s, size_t n, int k)
{
    size_t m = kw_lens[k];
    int c = memcmp(s, kw_texts[k], n < m ? n : m);
    if (c != 0) return c;
    return n < m ? -1 : (n > m ? 1 : 0);
}

sdl_kw sdl_kw_lookup(const char *s, size_t n)
{
    if (n == 0 || n > 31) return KW_NONE; /* no keyword is longer */
    int lo = 1, hi = SDL_KW_LIMIT - 1;
    while (lo <= hi) {
        int mid = (lo + hi) / 2;
        int c = word_cmp(s, n, mid);
        if (c == 0) {
            assert(mid > KW_NONE && mid < SDL_KW_LIMIT);
            return (sdl_kw)mid;
        }
        if (c < 0) hi = mid - 1;
        else lo = mid + 1;
    }
    return KW_NONE;
}

void sdl_scan_init(sdl_scanner *s, const char *file, const char *text, size_t len)
{
    memset(s, 0, sizeof *s);
    s->file = file;
    s->text = text;
    s->len = len;
    s->at.pos = 0;
    s->at.line = 1;
    s->at.col = 1;
    if (len >= 3 && memcmp(text, "\xEF\xBB\xBF", 3) == 0) s->at.pos = 3; /* UTF-8 byte order mark */
}

sdl_scan_pos sdl_scan_tell(const sdl_scanner *s) { return s->at; }
void sdl_scan_seek(sdl_scanner *s, sdl_scan_pos p)
{
    assert(p.pos <= s->len && p.line >= 1 && p.col >= 1); /* a position sdl_scan_tell gave */
    s->at = p;
}

static int peek_char(const sdl_scanner *s, size_t ahead)
{
    size_t i = s->at.pos + ahead;
    return i < s->len ? (unsigned char)s->text[i] : -1;
}

static void advance(sdl_scanner *s)
{
    if (s->at.pos >= s->len) return;
    char c = s->text[s->at.pos++];
    if (c == '\n') {
        s->at.line++;
        s->at.col = 1;
    } else if (c == '\r') {
        /* a lone CR ends a line too (old Mac files); CRLF counts once */
        if (peek_char(s, 0) != '\n') {
            s->at.line++;
            s->at.col = 1;
        }
    } else {
        s->at.col++;
    }
}

static src_loc here(const sdl_scanner *s)
{
    src_loc l = {s->file, s->at.line, s->at.col};
    return l;
}

/* Skip a block comment whose opening has been consumed; nests like POV-Ray. */
static int skip_block_comment(sdl_scanner *s)
{
    int depth = 1;
    while (depth > 0) {
        int c = peek_char(s, 0);
        if (c < 0) return 0;
        if (c == '/' && peek_char(s, 1) == '*') {
            advance(s);
            advance(s);
            depth++;
        } else if (c == '*' && peek_char(s, 1) == '/') {
            advance(s);
            advance(s);
            depth--;
        } else {
            advance(s);
        }
    }
    return 1;
}

/* Skip blanks and comments. Returns 0 (with err set, *at = comment start) on
 * an unterminated comment. */
static int skip_space(sdl_scanner *s, src_loc *at)
{
    for (;;) {
        int c = peek_char(s, 0);
        if (c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v') {
            advance(s);
        } else if (c == '/' && peek_char(s, 1) == '/') {
            while (peek_char(s, 0) >= 0 && peek_char(s, 0) != '\n' && peek_char(s, 0) != '\r') advance(s);
        } else if (c == '/' && peek_char(s, 1) == '*') {
            *at = here(s);
            advance(s);
            advance(s);
            if (!skip_block_comment(s)) {
                snprintf(s->err, sizeof s->err, "unterminated comment");
                return 0;
            }
        } else {
            return 1;
        }
    }
}

static int is_digit(int c) { return c >= '0' && c <= '9'; }
static int is_ident_start(int c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
static int is_ident_char(int c) { return is_ident_start(c) || is_digit(c); }

/* Correctly rounded value of a short decimal without calling strtod: at
 * most 15 significant digits and a power of ten up to 22 (both exact in a
 * double, so one multiplication or division rounds once). 0 if the number
 * does not qualify. */
static int fast_number(const char *p, size_t n, double *out)
{
    static const double pow10[23] = {1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11,
                                     1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
    unsigned long long m = 0;
    int digits = 0, scale = 0, seen_dot = 0;
    size_t i = 0;
    for (; i < n; i++) {
        char c = p[i];
        if (c >= '0' && c <= '9') {
            if (m == 0 && c == '0') {
                if (seen_dot) scale--;
                continue;
            }
            if (++digits > 15) return 0;
            m = m * 10 + (unsigned)(c - '0');
            if (seen_dot) scale--;
        } else if (c == '.' && !seen_dot) {
            seen_dot = 1;
        } else {
            break;
        }
    }
    if (i < n) { /* exponent */
        if (p[i] != 'e' && p[i] != 'E') return 0;
        i++;
        int sign = 1, e = 0;
        if (i < n && (p[i] == '+' || p[i] == '-')) sign = p[i++] == '-' ? -1 : 1;
        if (i >= n) return 0;
        for (; i < n; i++) {
            if (p[i] < '0' || p[i] > '9' || e > 1000) return 0;
            e = e * 10 + (p[i] - '0');
        }
        scale += sign * e;
    }
    if (m == 0) {
        *out = 0.0;
        return 1;
    }
    if (scale < -22 || scale > 22) return 0;
    *out = scale < 0 ? (double)m / pow10[-scale] : (double)m * pow10[scale];
    return 1;
}

/* number: digits [ '.' [digits] ] [ exponent ] | '.' digits [ exponent ] */
static void scan_number(sdl_scanner *s, sdl_token *t)
{
    size_t start = s->at.pos;
    while (is_digit(peek_char(s, 0))) advance(s);
    if (peek_char(s, 0) == '.' && (is_digit(peek_char(s, 1)) || !is_ident_start(peek_char(s, 1)))) {
        advance(s);
        while (is_digit(peek_char(s, 0))) advance(s);
    }
    int e = peek_char(s, 0);
    if (e == 'e' || e == 'E') {
        int k = (peek_char(s, 1) == '+' || peek_char(s, 1) == '-') ? 2 : 1;
        if (is_digit(peek_char(s, (size_t)k))) {
            for (int i = 0; i < k; i++) advance(s);
            while (is_digit(peek_char(s, 0))) advance(s);
        }
    }
    size_t n = s->at.pos - start;
    t->kind = TOK_NUMBER;
    if (!fast_number(s->text + start, n, &t->num)) {
        char buf[128];
        if (n >= sizeof buf) n = sizeof buf - 1;
        memcpy(buf, s->text + start, n);
        buf[n] = 0;
        t->num = strtod(buf, NULL);
    }
    t->text = s->text + start;
    t->len = (int)(s->at.pos - start);
}

static void scan_string(sdl_scanner *s, sdl_token *t)
{
    advance(s); /* opening quote */
    size_t start = s->at.pos;
    for (;;) {
        int c = peek_char(s, 0);
        if (c < 0) {
            t->kind = TOK_ERROR;
            snprintf(s->err, sizeof s->err, "unterminated string");
            return;
        }
        if (c == '"') break;
        if (c == '\\' && peek_char(s, 1) >= 0) advance(s);
        advance(s);
    }
    t->kind = TOK_STRING;
    t->text = s->text + start;
    t->len = (int)(s->at.pos - start);
    advance(s); /* closing quote */
}

static void scan_word(sdl_scanner *s, sdl_token *t)
{
    size_t start = s->at.pos;
    while (is_ident_char(peek_char(s, 0))) advance(s);
    t->text = s->text + start;
    t->len = (int)(s->at.pos - start);
    t->kw = sdl_kw_lookup(t->text, (size_t)t->len);
    t->kind = t->kw != KW_NONE ? TOK_KEYWORD : TOK_IDENT;
}

typedef struct { char c, next; sdl_tok_kind one, two; } punct_rule;

static const punct_rule puncts[] = {
    {'<', '=', TOK_LT, TOK_LE}, {'>', '=', TOK_GT, TOK_GE}, {'!', '=', TOK_BANG, TOK_NE},
    {'{', 0, TOK_LBRACE, 0}, {'}', 0, TOK_RBRACE, 0}, {'(', 0, TOK_LPAREN, 0},
    {')', 0, TOK_RPAREN, 0}, {'[', 0, TOK_LBRACKET, 0}, {']', 0, TOK_RBRACKET, 0},
    {'=', 0, TOK_EQ, 0}, {',', 0, TOK_COMMA, 0}, {';', 0, TOK_SEMI, 0},
    {'+', 0, TOK_PLUS, 0}, {'-', 0, TOK_MINUS, 0}, {'*', 0, TOK_STAR, 0},
    {'/', 0, TOK_SLASH, 0}, {'.', 0, TOK_DOT, 0}, {'?', 0, TOK_QUESTION, 0},
    {':', 0, TOK_COLON, 0}, {'&', 0, TOK_AMP, 0}, {'|', 0, TOK_BAR, 0},
    {'#', 0, TOK_HASH, 0},
};

static void scan_punct(sdl_scanner *s, sdl_token *t, int c)
{
    for (size_t i = 0; i < sizeof puncts / sizeof puncts[0]; i++) {
        if (puncts[i].c != c) continue;
        t->text = s->text + s->at.pos;
        advance(s);
        t->kind = puncts[i].one;
        t->len = 1;
        if (puncts[i].next && peek_char(s, 0) == puncts[i].next) {
            advance(s);
            t->kind = puncts[i].two;
            t->len = 2;
        }
        return;
    }
    t->kind = TOK_ERROR;
    t->text = s->text + s->at.pos;
    t->len = 1;
    if (c >= 32 && c < 127)
        snprintf(s->err, sizeof s->err, "unexpected character '%c'", c);
    else
        snprintf(s->err, sizeof s->err, "unexpected character (byte 0x%02x)", (unsigned)c);
    advance(s);
}

sdl_token sdl_scan_next(sdl_scanner *s)
{
    sdl_token t;
    memset(&t, 0, sizeof t);
    s->err[0] = 0;
    src_loc comment_at = here(s);
    if (!skip_space(s, &comment_at)) {
        t.kind = TOK_ERROR;
        t.loc = comment_at;
        return t;
    }
    t.loc = here(s);
    int c = peek_char(s, 0);
    if (c < 0) {
        t.kind = TOK_EOF;
        t.text = s->text + s->len;
    } else if (is_digit(c) || (c == '.' && is_digit(peek_char(s, 1)))) {
        scan_number(s, &t);
    } else if (is_ident_start(c)) {
        scan_word(s, &t);
    } else if (c == '"') {
        scan_string(s, &t);
    } else {
        scan_punct(s, &t, c);
    }
    /* a token never reaches past the text, and the scan moves on */
    assert(s->at.pos <= s->len);
    assert(t.kind == TOK_EOF || t.kind == TOK_ERROR || s->at.pos > 0);
    return t;
}

static int hex_value(int c)
{
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

/* Append a code point as UTF-8 (or '?' if it does not fit). */
static size_t put_utf8(char *out, size_t o, size_t cap, unsigned cp)
{
    char b[4];
    size_t n;
    if (cp < 0x80) { b[0] = (char)cp; n = 1; }
    else if (cp < 0x800) { b[0] = (char)(0xC0 | (cp >> 6)); b[1] = (char)(0x80 | (cp & 0x3F)); n = 2; }
    else { b[0] = (char)(0xE0 | (cp >> 12)); b[1] = (char)(0x80 | ((cp >> 6) & 0x3F)); b[2] = (char)(0x80 | (cp & 0x3F)); n = 3; }
    for (size_t i = 0; i < n && o + 1 < cap; i++) out[o++] = b[i];
    return o;
}

size_t sdl_scan_unescape(const sdl_token *t, char *out, size_t cap)
{
    size_t o = 0;
    if (cap == 0) return 0;
    for (int i = 0; i < t->len && o + 1 < cap; i++) {
        char c = t->text[i];
        if (c != '\\' || i + 1 >= t->len) {
            out[o++] = c;
            continue;
        }
        char e = t->text[++i];
        switch (e) {
        case 'n': out[o++] = '\n'; break;
        case 't': out[o++] = '\t'; break;
        case 'r': out[o++] = '\r'; break;
        case 'a': out[o++] = '\a'; break;
        case 'b': out[o++] = '\b'; break;
        case 'f': out[o++] = '\f'; break;
        case 'v': out[o++] = '\v'; break;
        case '0': out[o++] = '\0'; break;
        case 'u': {
            unsigned cp = 0;
            int k = 0;
            while (k < 4 && i + 1 < t->len && hex_value((unsigned char)t->text[i + 1]) >= 0) {
                cp = cp * 16 + (unsigned)hex_value((unsigned char)t->text[++i]);
                k++;
            }
            o = put_utf8(out, o, cap, cp);
            break;
        }
        default: out[o++] = e; break; /* \\ \" \' and unknown escapes keep the char */
        }
    }
    out[o] = 0;
    return o;
}

const char *sdl_tok_kind_text(sdl_tok_kind k)
{
    static const char *const names[] = {
        "end of file", "invalid token", "number", "string", "identifier", "keyword",
        "{", "}", "(", ")", "[", "]", "<", ">", "<=", ">=", "=", "!=",
        ",", ";", "+", "-", "*", "/", ".", "?", ":", "!", "&", "|", "#"};
    return (k >= 0 && (size_t)k < sizeof names / sizeof names[0]) ? names[k] : "?";
}

const char *sdl_tok_describe(const sdl_token *t, char *buf, size_t cap)
{
    switch (t->kind) {
    case TOK_EOF: snprintf(buf, cap, "end of file"); break;
    case TOK_NUMBER: snprintf(buf, cap, "number %.*s", t->len > 40 ? 40 : t->len, t->text); break;
    case TOK_STRING: snprintf(buf, cap, "string \"%.*s\"", t->len > 40 ? 40 : t->len, t->text); break;
    case TOK_IDENT:
    case TOK_KEYWORD: snprintf(buf, cap, "'%.*s'", t->len > 60 ? 60 : t->len, t->text); break;
    default: snprintf(buf, cap, "'%s'", sdl_tok_kind_text(t->kind)); break;
    }
    return buf;
}
