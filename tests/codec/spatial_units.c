/*
 * spatial_units.c — unit checks of the codec for spatial requests (DESIGN.md 7.3).
 *
 * How it fits: codec_test.c calls these before the data folders.  They read
 * spatial requests with req_parse_codec_only, so they hold whether or not
 * the core can build spatial models yet:
 *   unit_spatial_diag    a core diagnostic on a spatial field maps to the
 *                        pointer of the field the user wrote (E for EA of a
 *                        section in material form, with "EA = E*A" in the
 *                        message; twist_deg, flap_direction, inertia, z ...);
 *   unit_spatial_result  codec_result_encode writes 6 numbers per node and
 *                        joint and per shape row, and "spatial": true,
 *                        "dof_per_node": 6 in "model", for a spatial request;
 *                        a planar one keeps 3 numbers and no new key.  The
 *                        model (sizes, joint -> node) is a planar one of the
 *                        same topology: the encoder takes only those from it.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "codec_test.h"

/* Two spatial sections in both forms, a node with z, twist, e3, a point-mass inertia. */
static const char *unit_spatial_request =
    "{\"structure\": {\"joints\": {\"O\": [0, 0], \"C\": [1, 0, 0.5], \"P\": [2, 0, 0.5]},"
    " \"sections\": {\"m\": {\"E\": 7e10, \"G\": 2.6e10, \"A\": 4e-4, \"I_flap\": 2e-7,"
    " \"I_edge\": 8e-7, \"J\": 5e-7, \"mass_per_length\": 1.2},"
    " \"s\": {\"EA\": 2.8e7, \"EI_flap\": 1.4e4, \"EI_edge\": 5.6e4, \"GJ\": 1.3e4,"
    " \"mass_per_length\": 1.2, \"flap_inertia\": 6e-4}},"
    " \"members\": [{\"from\": \"O\", \"to\": \"C\", \"section\": \"m\", \"elements\": 1},"
    " {\"from\": \"C\", \"to\": \"P\", \"section\": \"s\", \"elements\": 1, \"twist_deg\": 30,"
    " \"flap_direction\": [0, 0, 1]}],"
    " \"point_masses\": [{\"joint\": \"P\", \"mass\": 1, \"inertia\": [0.1, 0.2, 0.3]}],"
    " \"clamp\": \"O\"}, \"analysis\": {\"omega\": 1}}";

/* Parse text with the codec alone; NULL (and a failure) when it does not validate. */
static codec_request *unit_parse(test_case *tc, const char *text, const char *what)
{
    codec_errors *errs = codec_errors_new();
    codec_request *req = NULL;

    if (!errs || req_parse_codec_only(&req, text, strlen(text), NULL, errs) != SM_OK)
        fail(tc, "%s rejected: '%s' %s", what, codec_errors_pointer(errs, 0),
             codec_errors_message(errs, 0));
    codec_errors_free(errs);
    return req;
}

void unit_spatial_diag(test_case *tc)
{
    static const struct {
        sm_item item;
        int index;
        const char *field;
        const char *pointer;
        const char *relation; /* appended to the message as " (...)", or NULL */
    } map[] = {
        /* sections in sorted order: m (material form) = 0, s (stiffness form) = 1 */
        {SM_ITEM_SECTION, 0, "EA", "/structure/sections/m/E", "EA = E*A"},
        {SM_ITEM_SECTION, 0, "EI_flap", "/structure/sections/m/I_flap", "EI_flap = E*I_flap"},
        {SM_ITEM_SECTION, 0, "EI_edge", "/structure/sections/m/I_edge", "EI_edge = E*I_edge"},
        {SM_ITEM_SECTION, 0, "GJ", "/structure/sections/m/J", "GJ = G*J"},
        {SM_ITEM_SECTION, 0, "ip_over_a", "/structure/sections/m", "I_p/A = (I_flap + I_edge)/A"},
        {SM_ITEM_SECTION, 0, "flap_inertia", "/structure/sections/m/flap_inertia", NULL},
        {SM_ITEM_SECTION, 0, "mu", "/structure/sections/m/mass_per_length", NULL},
        {SM_ITEM_SECTION, 1, "EA", "/structure/sections/s/EA", NULL},
        {SM_ITEM_SECTION, 1, "EI_edge", "/structure/sections/s/EI_edge", NULL},
        {SM_ITEM_SECTION, 1, "i_edge", "/structure/sections/s/edge_inertia", NULL},
        {SM_ITEM_SECTION, 1, "edge_inertia", "/structure/sections/s/edge_inertia", NULL},
        {SM_ITEM_SECTION, 1, "ip_over_a", "/structure/sections/s",
         "I_p/A = (flap_inertia + edge_inertia)/mass_per_length"},
        {SM_ITEM_SECTION, 1, "E", "/structure/sections/s", NULL},
        {SM_ITEM_MEMBER, 0, "GJ", "/structure/sections/m/J", "GJ = G*J"},
        {SM_ITEM_MEMBER, 1, "EA", "/structure/sections/s/EA", NULL},
        {SM_ITEM_MEMBER, 1, "twist_deg", "/structure/members/1/twist_deg", NULL},
        {SM_ITEM_MEMBER, 1, "flap_direction", "/structure/members/1/flap_direction", NULL},
        {SM_ITEM_MEMBER, 0, "flap_direction", "/structure/members/0/flap_direction", NULL},
        {SM_ITEM_MEMBER, 1, "e3", "/structure/members/1/flap_direction", NULL},
        {SM_ITEM_MEMBER, 0, "twist", "/structure/members/0/twist_deg", NULL},
        {SM_ITEM_POINT_MASS, 0, "inertia", "/structure/point_masses/0/inertia", NULL},
        /* joints in sorted order: C = 0, O = 1 (given [0, 0]: z = 0 written out), P = 2 */
        {SM_ITEM_JOINT, 0, "z", "/structure/joints/C/2", NULL},
        {SM_ITEM_JOINT, 1, "z", "/structure/joints/O/2", NULL},
        {SM_ITEM_JOINT, 2, "x", "/structure/joints/P/0", NULL},
        {SM_ITEM_OPTIONS, -1, "substructure_modes", "/analysis/substructure_modes", NULL},
        {SM_ITEM_OPTIONS, -1, "basis", "/analysis/substructure_modes", NULL},
    };
    static const char *planar =
        "{\"structure\": {\"joints\": {\"O\": [0, 0], \"C\": [1, 0]},"
        " \"sections\": {\"al\": {\"E\": 1, \"A\": 1, \"I\": 1, \"mass_per_length\": 1}},"
        " \"members\": [{\"from\": \"O\", \"to\": \"C\", \"section\": \"al\", \"elements\": 1}],"
        " \"clamp\": \"O\"}, \"analysis\": {\"omega\": 1}}";
    codec_errors *errs = codec_errors_new();
    codec_request *req = unit_parse(tc, unit_spatial_request, "spatial diag request");
    codec_request *preq = unit_parse(tc, planar, "planar diag request");
    char want[300];
    size_t k;

    if (!req || !preq || !errs)
        goto done;
    for (k = 0; k < sizeof(map) / sizeof(map[0]); k++) {
        sm_diag d;
        memset(&d, 0, sizeof(d));
        d.status = SM_INVALID_INPUT;
        d.item = map[k].item;
        d.item_index = map[k].index;
        snprintf(d.field, sizeof(d.field), "%s", map[k].field);
        snprintf(d.message, sizeof(d.message), "spatial diag %zu", k);
        if (map[k].relation)
            snprintf(want, sizeof(want), "spatial diag %zu (%s)", k, map[k].relation);
        else
            snprintf(want, sizeof(want), "spatial diag %zu", k);
        codec_errors_clear(errs);
        if (codec_diag_error(req, &d, errs) != SM_OK || codec_errors_count(errs) != 1 ||
            strcmp(codec_errors_pointer(errs, 0), map[k].pointer) ||
            strcmp(codec_errors_message(errs, 0), want))
            fail(tc, "spatial diag %zu (%s) -> '%s' \"%s\", expected '%s' \"%s\"", k,
                 map[k].field, codec_errors_pointer(errs, 0), codec_errors_message(errs, 0),
                 map[k].pointer, want);
    }
    {
        /* a planar joint has no z: the joint itself */
        sm_diag d;
        memset(&d, 0, sizeof(d));
        d.status = SM_INVALID_INPUT;
        d.item = SM_ITEM_JOINT;
        d.item_index = 0;
        snprintf(d.field, sizeof(d.field), "z");
        codec_errors_clear(errs);
        if (codec_diag_error(preq, &d, errs) != SM_OK ||
            strcmp(codec_errors_pointer(errs, 0), "/structure/joints/C"))
            fail(tc, "planar joint z -> '%s'", codec_errors_pointer(errs, 0));
    }
done:
    codec_request_free(req);
    codec_request_free(preq);
    codec_errors_free(errs);
}

/* doc's rows at key of obj: n rows of dof numbers, row k starting with first[k]. */
static void unit_rows(test_case *tc, const json_t *rows, size_t n, size_t dof, const char *what)
{
    const json_t *row;
    size_t i;

    if (!json_is_array(rows) || json_array_size(rows) != n) {
        fail(tc, "%s: not %zu rows", what, n);
        return;
    }
    json_array_foreach(rows, i, row)
        if (json_array_size(row) != dof ||
            json_number_value(json_array_get(row, 0)) != (double)(10 * i))
            fail(tc, "%s: row %zu is not %zu numbers starting with %zu", what, i, dof, 10 * i);
}

/* Encode a one-speed result with node_dof dof for request req on model m; check its rows. */
static void unit_encode(test_case *tc, const codec_request *req, const sm_model *m, int dof)
{
    enum { NODES = 3, ELEMENTS = 2 };
    double nodes[6 * NODES], re[6 * NODES], im[6 * NODES], force[ELEMENTS] = {1, 2};
    double freq = 3, er = 0, ei = 3, mac = -1;
    int prev = -1, k;
    sm_case c;
    sm_result res = {1, &c, 0, NULL, 0, NULL, 0};
    json_t *doc = NULL, *model, *eq, *shape;
    const char *what = dof == 6 ? "spatial result" : "planar result";

    for (k = 0; k < 6 * NODES; k++) { /* row i of dof numbers starts with 10 i */
        nodes[k] = k % dof ? 0.5 : 10.0 * (k / dof);
        re[k] = nodes[k];
        im[k] = nodes[k];
    }
    memset(&c, 0, sizeof(c));
    c.omega = 1;
    c.status = SM_CASE_SOLVED;
    c.converged = 1;
    c.n_nodes = NODES;
    c.node_dof = dof;
    c.nodes = nodes;
    c.n_elements = ELEMENTS;
    c.axial_force = force;
    c.stable = 1;
    c.n_modes = 1;
    c.frequency = &freq;
    c.eig_re = &er;
    c.eig_im = &ei;
    c.mac_to_previous = &mac;
    c.previous_index = &prev;
    c.shape_re = re;
    c.shape_im = im;
    if (codec_result_encode(&doc, req, m, &res) != SM_OK) {
        fail(tc, "%s: codec_result_encode failed", what);
        return;
    }
    model = json_object_get(doc, "model");
    if (dof == 6 && (!json_is_true(json_object_get(model, "spatial")) ||
                     json_integer_value(json_object_get(model, "dof_per_node")) != 6 ||
                     json_object_size(model) != 6 + (json_object_get(model, "members") != NULL)))
        fail(tc, "%s: model lacks \"spatial\": true, \"dof_per_node\": 6", what);
    if (dof == 6 && json_object_get(model, "members") &&
        (json_array_size(json_object_get(model, "members")) !=
             (size_t)codec_request_structure(req)->n_members ||
         json_array_size(json_object_get(json_array_get(json_object_get(model, "members"), 0),
                                         "nodes")) < 2))
        fail(tc, "%s: model.members is not one layout per member with its nodes", what);
    if (dof == 3 && json_object_size(model) != 4)
        fail(tc, "%s: model has %zu keys, expected nodes, elements, frames, coordinates", what,
             json_object_size(model));
    eq = json_object_get(json_array_get(json_object_get(doc, "cases"), 0), "equilibrium");
    unit_rows(tc, json_object_get(eq, "nodes"), NODES, (size_t)dof, "equilibrium.nodes");
    if (json_array_size(json_object_get(json_object_get(eq, "joints"), "C")) != (size_t)dof ||
        json_array_size(json_object_get(json_object_get(eq, "joints"), "O")) != (size_t)dof)
        fail(tc, "%s: joint rows are not %d numbers", what, dof);
    shape = json_object_get(json_array_get(json_object_get(json_array_get(
                                json_object_get(doc, "cases"), 0), "modes"), 0), "shape");
    unit_rows(tc, json_object_get(shape, "re"), NODES, (size_t)dof, "shape.re");
    unit_rows(tc, json_object_get(shape, "im"), NODES, (size_t)dof, "shape.im");
    json_decref(doc);
}

void unit_spatial_result(test_case *tc)
{
    static const char *spatial =
        "{\"structure\": {\"joints\": {\"O\": [0, 0, 0], \"C\": [1, 0, 0]},"
        " \"sections\": {\"s\": {\"EA\": 1e7, \"EI_flap\": 1e4, \"EI_edge\": 2e4, \"GJ\": 1e4,"
        " \"mass_per_length\": 1}},"
        " \"members\": [{\"from\": \"O\", \"to\": \"C\", \"section\": \"s\", \"elements\": 2}],"
        " \"clamp\": \"O\"}, \"analysis\": {\"omega\": 1}}";
    static const char *planar =
        "{\"structure\": {\"joints\": {\"O\": [0, 0], \"C\": [1, 0]},"
        " \"sections\": {\"s\": {\"E\": 1e11, \"A\": 1e-4, \"I\": 1e-7, \"mass_per_length\": 1}},"
        " \"members\": [{\"from\": \"O\", \"to\": \"C\", \"section\": \"s\", \"elements\": 2}],"
        " \"clamp\": \"O\"}, \"analysis\": {\"omega\": 1}}";
    codec_request *sreq = unit_parse(tc, spatial, "spatial result request");
    codec_request *preq = unit_parse(tc, planar, "planar result request");
    codec_errors *errs = codec_errors_new();
    sm_model *m = NULL, *ms = NULL;

    if (!sreq || !preq || !errs)
        goto done;
    if (codec_model_new(&m, preq, errs, NULL) != SM_OK) {
        fail(tc, "planar model for the result rows: '%s' %s", codec_errors_pointer(errs, 0),
             codec_errors_message(errs, 0));
        goto done;
    }
    if (codec_model_new(&ms, sreq, errs, NULL) != SM_OK) {
        fail(tc, "spatial model for the result rows: '%s' %s", codec_errors_pointer(errs, 0),
             codec_errors_message(errs, 0));
        goto done;
    }
    unit_encode(tc, sreq, ms, 6);
    unit_encode(tc, preq, m, 3);
done:
    sm_model_free(m);
    sm_model_free(ms);
    codec_errors_free(errs);
    codec_request_free(sreq);
    codec_request_free(preq);
}
