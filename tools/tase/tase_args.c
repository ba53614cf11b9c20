/* tase: argument parsing shared by the commands. An option with a value
 * is given at most once, a value that starts with "--" is the next option,
 * and negative numbers are values where numbers are expected
 * (docs/TOOLS.md). */
#include <stdlib.h>
#include <string.h>

#include "tase_cli.h"

/* An option with a value is given once: a second one is an error, not
 * the silent winner. */
static void opt_once(cli_args_t *a, const char *name)
{
    unsigned k;
    for (k = 0; k < a->nseen; k++) {
        if (strcmp(a->seen[k], name) == 0) {
            tk_usage_error("option %s given twice", name);
        }
    }
    if (a->nseen < CLI_SEEN_MAX) {
        a->seen[a->nseen++] = name;
    }
}

/* If argv[i] is option `name` (with "--name V" or "--name=V" when has_arg),
 * consume it and return true; *val gets the value. A separate value that
 * starts with "--" is the next option, so the value is missing (numbers
 * such as -5 are values). */
bool cli_opt(cli_args_t *a, const char *name, bool has_arg, const char **val)
{
    const char *s = a->argv[a->i];
    size_t n = strlen(name);
    if (a->dashdash || strncmp(s, name, n) != 0) {
        return false;
    }
    if (s[n] == '\0') {
        if (has_arg) {
            if (a->i + 1 >= a->argc || strncmp(a->argv[a->i + 1], "--", 2) == 0) {
                tk_usage_error("option %s needs a value", name);
            }
            opt_once(a, name);
            *val = a->argv[++a->i];
        }
        a->i++;
        return true;
    }
    if (s[n] == '=' && has_arg) {
        opt_once(a, name);
        *val = s + n + 1;
        a->i++;
        return true;
    }
    return false;
}

/* --help, -h and "--" */
bool cli_common_opt(cli_args_t *a)
{
    const char *s = a->argv[a->i];
    if (a->dashdash) {
        return false;
    }
    if (strcmp(s, "--help") == 0 || strcmp(s, "-h") == 0) {
        cli_print_usage(a);
        exit(TK_EXIT_OK);
    }
    if (strcmp(s, "--") == 0) {
        a->dashdash = true;
        a->i++;
        return true;
    }
    return false;
}

/* Whether argv[i] is an argument rather than an option: after "--", "-"
 * (standard input), anything not starting with '-', and, where numbers are
 * expected, anything starting with a single '-' (no such option is left
 * there: -h is taken first): a negative number, or a bad one its parser
 * names ("bad pan '-inf': not a number", not "unknown option"). */
bool cli_is_arg(const cli_args_t *a, bool numbers)
{
    const char *s = a->argv[a->i];
    double x;
    return a->dashdash || s[0] != '-' || s[1] == '\0' ||
           (numbers && (s[1] != '-' || tk_parse_real(s, &x) == TK_NUM_OK));
}

/* --baud N */
bool cli_baud_opt(cli_args_t *a, long *baud)
{
    const char *v;
    long long n;
    if (!cli_opt(a, "--baud", true, &v)) {
        return false;
    }
    if (tk_parse_int(v, 1, 4000000, &n, NULL) != TK_NUM_OK) {
        tk_usage_error("bad --baud value '%s'", v);
    }
    *baud = (long)n;
    return true;
}

bool cli_link_opt(cli_args_t *a, cli_link_opts_t *l)
{
    if (cli_baud_opt(a, &l->baud)) {
        l->baud_given = true;
        return true;
    }
    {
        static const char *const names[3] = {"--serial", "--can", "--record"};
        const char **vals[3];
        size_t k;
        vals[0] = &l->serial;
        vals[1] = &l->can;
        vals[2] = &l->record;
        for (k = 0; k < 3u; k++) {
            if (cli_opt(a, names[k], true, vals[k])) {
                if (*vals[k][0] == '\0') {
                    tk_usage_error("option %s needs a value", names[k]); /* --can "" */
                }
                return true;
            }
        }
    }
    return false;
}

long long cli_int_opt_value(const char *name, const char *v, long long min, long long max)
{
    long long n;
    if (tk_parse_int(v, min, max, &n, NULL) != TK_NUM_OK) {
        tk_usage_error("bad %s value '%s' (expected an integer %lld..%lld)", name, v, min, max);
    }
    return n;
}

void cli_bad_arg(const cli_args_t *a)
{
    const char *s = a->argv[a->i];
    if (!a->dashdash && s[0] == '-' && s[1] != '\0') {
        tk_usage_error("unknown option '%s' (see --help)", s);
    }
    tk_usage_error("unexpected argument '%s' (see --help)", s);
}

bool cli_req_opt(cli_args_t *a, cli_req_opts_t *r)
{
    const char *v;
    if (cli_opt(a, "--timeout", true, &v)) {
        r->timeout_ms = (uint32_t)cli_int_opt_value("--timeout", v, 1, 600000);
        return true;
    }
    if (cli_opt(a, "--retries", true, &v)) {
        r->retries = (uint8_t)cli_int_opt_value("--retries", v, 0, 20);
        return true;
    }
    if (cli_opt(a, "--json", false, &v)) {
        r->json = true;
        return true;
    }
    return false;
}

/* x as a plain decimal number (no exponent; at most two decimals, no
 * trailing zeros): -21474836.48, 180, 0.01. */
static const char *plain_number(double x, char *buf, size_t cap)
{
    size_t n;
    snprintf(buf, cap, "%.2f", x);
    n = strlen(buf);
    while (n > 0 && buf[n - 1] == '0') {
        buf[--n] = '\0';
    }
    if (n > 0 && buf[n - 1] == '.') {
        buf[--n] = '\0';
    }
    return buf;
}

/* A decimal number argument in [lo, hi] (what names it in messages). */
double cli_real_arg(const char *what, const char *v, double lo, double hi, const char *unit)
{
    double x;
    char a[48], b[48];
    if (tk_parse_real(v, &x) != TK_NUM_OK) {
        tk_usage_error("bad %s '%s': not a number (decimal, e.g. -12.5)", what, v);
    }
    if (!(x >= lo && x <= hi)) {
        tk_usage_error("bad %s '%s': out of range %s..%s %s", what, v,
                       plain_number(lo, a, sizeof(a)), plain_number(hi, b, sizeof(b)), unit);
    }
    return x;
}

long long cli_scaled_arg(const char *what, const char *v, double lo, double hi, const char *unit,
                         unsigned long mul)
{
    const char *p = v;
    unsigned long long whole = 0, carry = 0;
    const char *dot, *end;
    bool neg = *p == '-';
    bool up = false;
    (void)cli_real_arg(what, v, lo, hi, unit); /* syntax and range */
    if (*p == '+' || *p == '-') {
        p++;
    }
    for (; *p >= '0' && *p <= '9'; p++) {
        whole = whole * 10u + (unsigned)(*p - '0'); /* in range: a few digits */
    }
    dot = p;
    end = dot + strlen(dot);
    /* The fraction times mul, exactly: a digit at a time from the last,
     * as on paper; carry ends as its whole part, and the last digit
     * written (the first after the point) says whether what is left is
     * at least one half. */
    if (*dot == '.') {
        const char *q;
        for (q = end - 1; q > dot; q--) {
            unsigned long long t = (unsigned long long)(*q - '0') * mul + carry;
            up = t % 10u >= 5u;
            carry = t / 10u;
        }
    }
    whole = whole * mul + carry + (up ? 1u : 0u);
    return neg ? -(long long)whole : (long long)whole;
}
