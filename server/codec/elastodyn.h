/*
 * elastodyn.h — ElastoDyn mode-shape coefficients from a result document, and a patched
 * copy of an ElastoDyn deck (DESIGN.md 9.3).
 *
 * The numbers are the core's (sm_elastodyn_fit_modes); this module reads them out of a
 * stored result document, so the daemon (GET .../result?format=elastodyn) and the CLI
 * (`spinmodal export elastodyn`) give the same bytes, and writes them into a deck.
 */
#ifndef SPINMODAL_CODEC_ELASTODYN_H
#define SPINMODAL_CODEC_ELASTODYN_H

#include <stddef.h>

#include <jansson.h>

#include "spinmodal.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Values in a blade deck: BldFl1Sh(2..6), BldFl2Sh(2..6), BldEdgSh(2..6). */
#define CODEC_ED_BLADE_VALUES 15

/** A tower's fits (FA 1, FA 2, SS 1, SS 2) and deck values TwFAM1Sh(2..6) ... TwSSM2Sh(2..6). */
#define CODEC_ED_TOWER_FITS 4
#define CODEC_ED_TOWER_VALUES 20

/**
 * The fits of case ci (0-based) of a result document (borrowed), blade or tower: a blade
 * (member "blade", else the only member) gives 3 (flap 1, flap 2, edge 1), a tower form's
 * member ("tower") 4 (FA 1, FA 2, SS 1, SS 2: the root's rigid motion taken out, a degenerate
 * FA/SS pair turned to pure directions, DESIGN.md 9.3); *nfit their number, *names (may be
 * NULL) codec_ed_blade_names or codec_ed_tower_names.  Returns as codec_elastodyn_case.
 */
int codec_elastodyn_fits(const json_t *result, size_t ci, sm_ed_fit fits[CODEC_ED_TOWER_FITS],
                         int *nfit, const char *const **names, char *err, size_t errcap);

/**
 * The blade fits (flap 1, flap 2, edge 1: SM_ED_FLAP1...) of case ci (0-based) of a result
 * document (borrowed): its member "blade" (the blade form), else its only member, the `from`
 * joint taken as the flexible root.  Returns SM_OK, SM_NOMEM or SM_INVALID_INPUT with err
 * saying why (planar, no mode shapes or energies, no blade member, no such case, a case
 * without modes); a slot no mode qualified for has mode -1.
 */
int codec_elastodyn_case(const json_t *result, size_t ci, sm_ed_fit fits[SM_ED_BLADE_FITS],
                         char *err, size_t errcap);

/**
 * The ElastoDyn text of a result document: for each case, "!" comment lines (the case, each
 * fit's mode, frequency, label, energy share, residuals and tip-slope error, warnings) and
 * the fifteen lines "value   BldFl1Sh(2) - Flap mode 1, coeff of x^2" as in the NREL
 * files (codec_elastodyn_format; a shape with no qualifying mode has a comment instead).
 * *out receives a malloc'd NUL-terminated string (free), *len its length (may be NULL).
 * Returns SM_OK, SM_NOMEM or SM_INVALID_INPUT with err (as codec_elastodyn_case).
 */
int codec_result_elastodyn(char **out, size_t *len, const json_t *result, char *err, size_t errcap);

/** Room for one written coefficient (codec_elastodyn_format). */
#define CODEC_ED_TEXT 48

/**
 * The five coefficients C2..C6 of a fit as ElastoDyn text: seven significant digits on the
 * largest, the same decimals on all five, and C6 written as 1 minus the written C2..C5 (exact
 * in decimal), so the written values sum to 1 exactly.
 */
void codec_elastodyn_format(const double coef[5], char text[5][CODEC_ED_TEXT]);

/** The fifteen deck values of three blade fits as text (codec_elastodyn_format), in the deck's
 *  order (C2..C6 of each). */
void codec_elastodyn_blade_values(const sm_ed_fit fits[SM_ED_BLADE_FITS],
                                  char values[CODEC_ED_BLADE_VALUES][CODEC_ED_TEXT]);

/** The deck's names of those values: "BldFl1Sh(2)" ... "BldEdgSh(6)". */
extern const char *const codec_ed_blade_names[CODEC_ED_BLADE_VALUES];

/** The deck values of nfit fits (5 each, codec_elastodyn_format), in the fits' order. */
void codec_elastodyn_values(const sm_ed_fit *fits, int nfit, char values[][CODEC_ED_TEXT]);

/** The tower deck's names: "TwFAM1Sh(2)" ... "TwSSM2Sh(6)". */
extern const char *const codec_ed_tower_names[CODEC_ED_TOWER_VALUES];

/**
 * A copy of the ElastoDyn deck text[len] with the value of each parameter names[i] (the
 * first token of the line whose second token is that name, any case) replaced by the text
 * values[i] (codec_elastodyn_format's); every other byte (spacing, comments, CRLF or LF,
 * the lines' order) as it was.  *out receives a malloc'd NUL-terminated copy (free), *len
 * its length (may be NULL).  Returns SM_OK, SM_NOMEM or SM_INVALID_INPUT with err naming
 * the line or the name (a name missing or given twice, an empty value or one with blanks).
 */
int codec_elastodyn_patch(char **out, size_t *len, const char *text, size_t text_len,
                          const char *const *names, const char *const *values, int n, char *err,
                          size_t errcap);

#ifdef __cplusplus
}
#endif

#endif /* SPINMODAL_CODEC_ELASTODYN_H */
