/* apps/cli: the command-line helpers every fcm program shares — numbers with range checks
 * (NaN, infinities and trailing junk refused), comma lists, keyword choices, element names,
 * a table of options that is both parsed and printed as --help, and atomic output files
 * written through the library's atomic-file code (fcm_atomic_file in fcm/io.h).
 *
 * Every function that rejects its input prints one line "PROG: OPTION: what is wrong" on
 * stderr and returns 0; success returns 1. The programs exit 2 on a usage error. */
#ifndef FCM_APPS_CLI_H
#define FCM_APPS_CLI_H

#include <fcm/element.h>

#include <stdio.h>

/** Longest comma-list item, with its terminating NUL. */
#define CLI_TOKEN 32

/** Range ends: closed by default; these flags open them. */
enum { CLI_LO_OPEN = 1, CLI_HI_OPEN = 2 };

/** A finite number in the range [lo, hi] (ends opened by `bounds`) from all of `s`. */
int cli_double(const char *prog, const char *opt, const char *s, double lo, double hi,
               unsigned bounds, double *out);

/** A whole number (decimal, no fraction, no exponent) in [lo, hi] from all of `s`. */
int cli_int(const char *prog, const char *opt, const char *s, long long lo, long long hi,
            long long *out);

/** Split the comma list `s` into 1..cap non-empty items shorter than CLI_TOKEN. */
int cli_list(const char *prog, const char *opt, const char *s, char tok[][CLI_TOKEN], int cap,
             int *n);

/** The index of `s` in the NULL-terminated `names`; the message lists the valid names. */
int cli_choice(const char *prog, const char *opt, const char *s, const char *const *names,
               int *out);

/** An element name (tet4, tet10, hex8, hex20; any case) into `*(fcm_element_type *)dest`;
 *  usable as the `parse` function of a CLI_CUSTOM option. */
int cli_element(const char *prog, const char *opt, const char *s, void *dest);

/** Run the gnuplot script `body` (drawing to the PNG terminal of `size`, e.g. "900,600 font
 * ',11'") into `path`: the picture goes to a temporary, then is renamed. 1 on success or when
 * gnuplot is missing (said on stderr, naming the Debian package), 0 on an error. */
int cli_gnuplot_png(const char *prog, const char *size, const char *path, const char *body);

/** As cli_gnuplot_png(), keeping the script: `body` is written to `script` (a gnuplot script
 * that draws `path` when run again: `gnuplot script`), then run. The script is written even
 * when gnuplot is missing. 1 on success or when gnuplot is missing (said on stderr), 0 on an
 * error (said on stderr). */
int cli_gnuplot_script_png(const char *prog, const char *script, const char *size, const char *path,
                           const char *body);

/** Colours for the plots' series, distinguishable from each other, "#rrggbb": one per series
 * or piece; more series than this take a colour ramp with a colour box instead. */
#define CLI_PALETTE_SIZE 12
extern const char *const cli_palette[CLI_PALETTE_SIZE];

/** --backend petsc (or --backend=petsc) among the arguments: the PETSc options of the command
 * line (a single dash and a word, "-ksp_type", with the value after it unless that is an
 * option) are moved from argv into pargv (after the program name argv[0]; pargv has room for
 * *argc + 1 entries and ends with NULL); argv keeps the program's own options. Without
 * --backend petsc nothing moves (an unknown option stays an error for the program's parser). */
void cli_split_petsc_args(int *argc, char **argv, int *pargc, char **pargv);

/** A comma list of distinct element names into out[0..*n-1] (at most FCM_ELEMENT_COUNT). */
int cli_element_list(const char *prog, const char *opt, const char *s,
                     fcm_element_type out[FCM_ELEMENT_COUNT], int *n);

/** How an option's value is read into `dest`. */
typedef enum cli_kind {
  CLI_FLAG,   /* no value; int *dest = 1 */
  CLI_DOUBLE, /* double *dest, range lo..hi with `bounds` (*) */
  CLI_INT,    /* int *dest, whole number in [lo, hi] (*) */
  CLI_LLONG,  /* long long *dest, whole number in [lo, hi] (*) */
  CLI_STRING, /* const char **dest = the argument (non-empty) */
  CLI_CHOICE, /* int *dest = index into `choices` */
  CLI_CUSTOM  /* parse(prog, name, value, dest) */
} cli_kind;
/* (*) A number option whose `metavar` has k space-separated words ("X0 Y0 Z0") takes k
 *     values, as k arguments ("--box -1 -1 -1 1 1 1", not "--box=..."), into dest[0..k-1].
 *     The other kinds take one value. */

/** One option of a table; the table ends with an entry whose `name` is NULL. */
typedef struct cli_option {
  const char *name;           /* "--alpha" */
  const char *alias;          /* "-a", or NULL */
  cli_kind kind;              /* how the value is read */
  void *dest;                 /* where it goes (see cli_kind) */
  const char *metavar;        /* the value's name in --help ("A"); NULL for flags */
  const char *help;           /* help text; '\n' starts a continuation line */
  double lo, hi;              /* CLI_DOUBLE, CLI_INT, CLI_LLONG: the valid range */
  unsigned bounds;            /* CLI_DOUBLE: CLI_LO_OPEN | CLI_HI_OPEN */
  const char *const *choices; /* CLI_CHOICE */
  int (*parse)(const char *prog, const char *opt, const char *value, void *dest); /* CUSTOM */
  int *seen; /* set to 1 when the option is given; may be NULL */
} cli_option;

/** What cli_parse() found. */
typedef enum cli_result { CLI_ERROR = 0, CLI_OK = 1, CLI_HELP = 2 } cli_result;

/** Parse argv[1..argc-1] against `opts`. "-h" and "--help" return CLI_HELP (nothing else is
 *  parsed after them); "--name=value" and "--name value" are both accepted. Arguments not
 *  starting with '-' are positional: stored in `pos` (at most `max_pos`, count in *npos; `pos`
 *  may be NULL with max_pos 0). An unknown option, a missing or bad value, or too many
 *  positional arguments print a message and return CLI_ERROR. */
cli_result cli_parse(const char *prog, const cli_option *opts, int argc, char **argv,
                     const char **pos, int max_pos, int *npos);

/** cli_parse() as a program's option parsing uses it: "--help" prints help(stdout, opts) and
 *  gives the exit code 0, a usage error (its message printed) gives 2, and -1 means the
 *  arguments are parsed: go on. */
int cli_parse_args(const char *prog, const cli_option *opts, int argc, char **argv,
                   const char **pos, int max_pos, int *npos,
                   void (*help)(FILE *f, const cli_option *opts));

/** The options of `opts` as help lines: "  -a, --name METAVAR   help", the help column
 *  aligned, continuation lines indented to it; then "  -h, --help   this text". */
void cli_print_options(FILE *f, const cli_option *opts);

/** An output file replaced atomically: written to a temporary beside it, renamed over it by
 *  cli_output_commit(), removed by cli_output_abort() or a failed commit. */
typedef struct cli_output cli_output;

/** Open the temporary for `path`; returns its stream or NULL (message on stderr). */
FILE *cli_output_open(const char *prog, const char *path, cli_output **out);

/** Check the stream for write errors, flush, close and rename; releases *out (set to NULL).
 *  1 on success; 0 with a message naming the path, the target untouched. */
int cli_output_commit(const char *prog, cli_output **out);

/** Remove the temporary and release *out; accepts NULL and *out == NULL. */
void cli_output_abort(cli_output **out);

/** A CSV field of a number: ",v" (%.6g), or "," alone when v is negative or not finite (the
 *  programs' CSVs leave a figure that was not measured empty). */
void cli_csv_number(FILE *f, double v);

/** A CSV field of text: "," and `s` with commas turned into ';', double quotes into single
 *  ones and line breaks into spaces (the programs' CSVs have no quoting). */
void cli_csv_text(FILE *f, const char *s);

/** mkdir -p: create the directory `dir` and its missing parents. 1 when it exists afterwards;
 *  0 with a message (a path too long, a part that cannot be created or is not a directory). */
int cli_make_dirs(const char *prog, const char *dir);

/* Whether the output directory `dir` can be made by cli_make_dirs() without creating
 * anything: it, or its nearest existing ancestor, is a directory this process may write
 * into. 0 after printing why not ("<prog>: output path 'x' exists and is not a directory"). */
int cli_check_output_dir(const char *prog, const char *dir);

/* "<prog>: scene <name>: <message>" on stderr, without repeating the scene when the library's
 * message already starts with "scene <name>". */
void cli_report_scene_error(const char *prog, const char *name, const char *message);

#endif
