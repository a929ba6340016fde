/* SPDX-License-Identifier: MIT */
/*
 * _core.c - the CPython extension of the bsf Python package: a thin layer
 * over the library's public API (include/bsf), compiled together with the
 * library's own src/ files, the POSIX clock hook and the host tool's CARMEN
 * reader (see setup.py). Everything numeric stays in C; this file only moves
 * data between Python objects and the library's structs and turns every
 * error status into a Python exception (bsf.BsfError, a ValueError).
 *
 * The wrapper in bsf/__init__.py builds numpy arrays and dataclasses from the
 * plain tuples, bytes and dicts returned here, so this file needs no numpy
 * headers (no build dependency on numpy, no ABI coupling to its version).
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include <bsf/bsf.h>

#include "bsf_port_clock.h"
#include "carmen.h"

static PyObject *g_bsf_error; /* bsf.BsfError, subclass of ValueError */

static const char *status_name(bsf_status_t st)
{
    switch (st) {
    case BSF_OK: return "BSF_OK";
    case BSF_OK_CUT: return "BSF_OK_CUT";
    case BSF_ERR_ARG: return "BSF_ERR_ARG";
    case BSF_ERR_CAPACITY: return "BSF_ERR_CAPACITY";
    case BSF_ERR_PARAM: return "BSF_ERR_PARAM";
    case BSF_ERR_NUMERIC: return "BSF_ERR_NUMERIC";
    case BSF_ERR_DEGENERATE: return "BSF_ERR_DEGENERATE";
    case BSF_ERR_BUFFER: return "BSF_ERR_BUFFER";
    case BSF_ERR_FORMAT: return "BSF_ERR_FORMAT";
    case BSF_ERR_CRC: return "BSF_ERR_CRC";
    case BSF_ERR_VERSION: return "BSF_ERR_VERSION";
    case BSF_ERR_UNSUPPORTED: return "BSF_ERR_UNSUPPORTED";
    }
    return "BSF_ERR_?";
}

/* Raise BsfError("<what>: <status text> (<NAME>)") with .status = st. */
static PyObject *raise_status(bsf_status_t st, const char *what)
{
    PyObject *msg = PyUnicode_FromFormat("%s: %s (%s)", what, bsf_status_str(st), status_name(st));
    PyObject *exc;
    if (msg == NULL) {
        return NULL;
    }
    exc = PyObject_CallFunctionObjArgs(g_bsf_error, msg, NULL);
    Py_DECREF(msg);
    if (exc == NULL) {
        return NULL;
    }
    {
        PyObject *code = PyLong_FromLong((long)st);
        if (code == NULL || PyObject_SetAttrString(exc, "status", code) != 0) {
            Py_XDECREF(code);
            Py_DECREF(exc);
            return NULL;
        }
        Py_DECREF(code);
    }
    PyErr_SetObject(g_bsf_error, exc);
    Py_DECREF(exc);
    return NULL;
}

/* Append item to list and drop the caller's reference to it: 0, or -1 with an
 * exception set (item NULL: the call that made it failed). */
static int list_append_new(PyObject *list, PyObject *item)
{
    int rc;
    if (item == NULL) {
        return -1;
    }
    rc = PyList_Append(list, item);
    Py_DECREF(item);
    return rc;
}

/* ---- parameters ------------------------------------------------------------ */

typedef enum { PT_INT, PT_FLOAT, PT_U16, PT_U8 } param_type_t;

typedef struct {
    const char *name;
    param_type_t type;
    size_t offset;
} param_desc_t;

#define PARAM(name, field, type)                                                                   \
    {                                                                                              \
        name, type, offsetof(bsf_params_t, field)                                                  \
    }

/* Every runtime parameter of bsf_params_t, named <stage>_<field>. */
static const param_desc_t g_params[] = {
    PARAM("falko_min_score_th", falko.min_score_th, PT_INT),
    PARAM("falko_min_range", falko.min_range, PT_FLOAT),
    PARAM("falko_max_range", falko.max_range, PT_FLOAT),
    PARAM("falko_subbeam", falko.subbeam, PT_INT),
    PARAM("falko_nms_radius", falko.nms_radius, PT_FLOAT),
    PARAM("falko_neigh_a", falko.neigh_a, PT_FLOAT),
    PARAM("falko_neigh_b", falko.neigh_b, PT_FLOAT),
    PARAM("falko_neigh_min_points", falko.neigh_min_points, PT_INT),
    PARAM("falko_b_ratio", falko.b_ratio, PT_FLOAT),
    PARAM("falko_grid_sectors", falko.grid_sectors, PT_INT),
    PARAM("falko_circular_sector_distance", falko.circular_sector_distance, PT_INT),
    PARAM("lc_jump_a", lc.jump_a, PT_FLOAT),
    PARAM("lc_jump_b", lc.jump_b, PT_FLOAT),
    PARAM("lc_split_min", lc.split_min, PT_FLOAT),
    PARAM("lc_split_sigmas", lc.split_sigmas, PT_FLOAT),
    PARAM("lc_min_turn", lc.min_turn, PT_FLOAT),
    PARAM("lc_curve_ratio", lc.curve_ratio, PT_FLOAT),
    PARAM("lc_floor", lc.floor, PT_FLOAT),
    PARAM("lc_max_side", lc.max_side, PT_FLOAT),
    PARAM("lc_apex_slack", lc.apex_slack, PT_FLOAT),
    PARAM("lc_min_side_len", lc.min_side_len, PT_FLOAT),
    PARAM("lc_max_range", lc.max_range, PT_FLOAT),
    PARAM("lc_join_grazing", lc.join_grazing, PT_U8),
    PARAM("lc_corner_evidence", lc.corner_evidence, PT_U8),
    PARAM("lc_min_side_points", lc.min_side_points, PT_U16),
    PARAM("bid_neigh_a", bid.neigh_a, PT_FLOAT),
    PARAM("bid_neigh_b", bid.neigh_b, PT_FLOAT),
    PARAM("bid_t_th", bid.t_th, PT_FLOAT),
    PARAM("bid_nms_radius", bid.nms_radius, PT_FLOAT),
    PARAM("bid_min_side_points", bid.min_side_points, PT_U16),
    PARAM("bid_max_iterations", bid.max_iterations, PT_U16),
    PARAM("bid_rel_tol", bid.rel_tol, PT_FLOAT),
    PARAM("sved_a", sved.a, PT_FLOAT),
    PARAM("sved_b", sved.b, PT_FLOAT),
    PARAM("sved_min_segment_points", sved.min_segment_points, PT_U16),
    PARAM("sved_max_gap_beams", sved.max_gap_beams, PT_U16),
    PARAM("sved_radius_max", sved.radius_max, PT_FLOAT),
    PARAM("sved_lookback", sved.lookback, PT_U8),
    PARAM("sved_reject_mixed", sved.reject_mixed, PT_U8),
    PARAM("sved_join_grazing", sved.join_grazing, PT_U8),
    PARAM("no_return_code", no_return.code, PT_FLOAT),
    PARAM("no_return_min_run", no_return.min_run, PT_U16),
    PARAM("rpos_alpha_max", rpos.alpha_max, PT_FLOAT),
    PARAM("rpos_eta", rpos.eta, PT_FLOAT),
    PARAM("rpos_min_segment_points", rpos.min_segment_points, PT_U16),
    PARAM("pdm_precision_spacing", pdm.precision_spacing, PT_FLOAT),
    PARAM("pdm_lambda_per_metre", pdm.lambda_per_metre, PT_FLOAT),
    PARAM("pdm_rel_tol", pdm.rel_tol, PT_FLOAT),
    PARAM("pdm_target_rms", pdm.target_rms, PT_FLOAT),
    PARAM("pdm_max_iterations", pdm.max_iterations, PT_U16),
    PARAM("pdm_refine_iterations", pdm.refine_iterations, PT_U16),
    PARAM("pdm_max_ctrl", pdm.max_ctrl, PT_U16),
    PARAM("pdm_footpoint_steps", pdm.footpoint_steps, PT_U8),
    PARAM("pdm_refine", pdm.refine, PT_U8),
    PARAM("pdm_bias_window", pdm.bias_window, PT_U8),
    PARAM("pdm_bias_ratio", pdm.bias_ratio, PT_FLOAT),
    PARAM("pdm_max_passes", pdm.max_passes, PT_U16),
    PARAM("split_dist", split_dist, PT_FLOAT),
    PARAM("trim_tails", trim_tails, PT_U8),
    PARAM("fit_passes", fit_passes, PT_U8),
    PARAM("fit_bin_length", fit_bin_length, PT_FLOAT),
};
#define N_PARAMS (sizeof g_params / sizeof g_params[0])

static PyObject *param_get(const bsf_params_t *p, const param_desc_t *d)
{
    const char *base = (const char *)p + d->offset;
    switch (d->type) {
    case PT_INT: {
        int v;
        memcpy(&v, base, sizeof v);
        return PyLong_FromLong(v);
    }
    case PT_FLOAT: {
        float v;
        memcpy(&v, base, sizeof v);
        return PyFloat_FromDouble((double)v);
    }
    case PT_U16: {
        uint16_t v;
        memcpy(&v, base, sizeof v);
        return PyLong_FromLong((long)v);
    }
    case PT_U8: {
        uint8_t v;
        memcpy(&v, base, sizeof v);
        return PyLong_FromLong((long)v);
    }
    }
    Py_RETURN_NONE;
}

/* Set one parameter from a Python value; 0 or -1 with an exception set. */
static int param_set(bsf_params_t *p, const param_desc_t *d, PyObject *value)
{
    char *base = (char *)p + d->offset;
    if (d->type == PT_FLOAT) {
        double v;
        float f;
        if (!PyFloat_Check(value) && !PyLong_Check(value)) {
            PyErr_Format(PyExc_TypeError, "parameter %s needs a number, got %.80s", d->name,
                         Py_TYPE(value)->tp_name);
            return -1;
        }
        v = PyFloat_AsDouble(value);
        if (v == -1.0 && PyErr_Occurred()) {
            return -1;
        }
        /* Every finite float is accepted, FLT_MAX included (the default of
         * lc_max_range): a double rounds to FLT_MAX below FLT_MAX + half
         * its ulp (2^128 - 2^103), and to infinity from there. */
        if (!isfinite(v) || fabs(v) >= 0x1.ffffffp127) {
            PyErr_Format(g_bsf_error, "parameter %s must be a finite float, got %R", d->name,
                         value);
            return -1;
        }
        f = fabs(v) > (double)FLT_MAX ? (v > 0.0 ? FLT_MAX : -FLT_MAX) : (float)v;
        memcpy(base, &f, sizeof f);
        return 0;
    }
    if (!PyLong_Check(value)) {
        PyErr_Format(PyExc_TypeError, "parameter %s needs an integer, got %.80s", d->name,
                     Py_TYPE(value)->tp_name);
        return -1;
    }
    {
        long lo = 0, hi = 0;
        int overflow = 0;
        const long v = PyLong_AsLongAndOverflow(value, &overflow);
        if (v == -1 && PyErr_Occurred()) {
            return -1;
        }
        switch (d->type) {
        case PT_INT:
            lo = -2147483647L;
            hi = 2147483647L;
            break;
        case PT_U16: hi = 65535; break;
        case PT_U8: hi = 255; break;
        case PT_FLOAT: break;
        }
        if (overflow != 0 || v < lo || v > hi) {
            PyErr_Format(g_bsf_error, "parameter %s = %R is outside %ld..%ld", d->name, value, lo,
                         hi);
            return -1;
        }
        if (d->type == PT_INT) {
            const int iv = (int)v;
            memcpy(base, &iv, sizeof iv);
        } else if (d->type == PT_U16) {
            const uint16_t uv = (uint16_t)v;
            memcpy(base, &uv, sizeof uv);
        } else {
            const uint8_t uv = (uint8_t)v;
            memcpy(base, &uv, sizeof uv);
        }
    }
    return 0;
}

static PyObject *params_to_dict(const bsf_params_t *p)
{
    PyObject *d = PyDict_New();
    size_t i;
    if (d == NULL) {
        return NULL;
    }
    for (i = 0; i < N_PARAMS; ++i) {
        PyObject *v = param_get(p, &g_params[i]);
        if (v == NULL || PyDict_SetItemString(d, g_params[i].name, v) != 0) {
            Py_XDECREF(v);
            Py_DECREF(d);
            return NULL;
        }
        Py_DECREF(v);
    }
    return d;
}

static int method_of(PyObject *name, bsf_method_t *out)
{
    const char *s;
    if (!PyUnicode_Check(name)) {
        PyErr_Format(PyExc_TypeError, "method must be a str, got %.80s", Py_TYPE(name)->tp_name);
        return -1;
    }
    s = PyUnicode_AsUTF8(name);
    if (s == NULL) {
        return -1;
    }
    *out = bsf_method_from_name(s);
    if (*out == BSF_METHOD_COUNT) {
        PyErr_Format(g_bsf_error,
                     "unknown method %R (lc-sved-pdm, falko-sved-pdm, bid-sved-pdm or rpos-lsba)",
                     name);
        return -1;
    }
    return 0;
}

/* Defaults of a method, then the caller's overrides, each checked on its own
 * so that an error names the parameter at fault. */
static int params_build(PyObject *method, PyObject *overrides, bsf_params_t *out)
{
    bsf_method_t m;
    bsf_status_t st;
    if (method_of(method, &m) != 0) {
        return -1;
    }
    *out = bsf_params_default(m);
    if (overrides != NULL && overrides != Py_None) {
        PyObject *key, *value;
        Py_ssize_t pos = 0;
        if (!PyDict_Check(overrides)) {
            PyErr_SetString(PyExc_TypeError, "parameters must be a dict");
            return -1;
        }
        while (PyDict_Next(overrides, &pos, &key, &value)) {
            const char *k = PyUnicode_Check(key) ? PyUnicode_AsUTF8(key) : NULL;
            size_t i;
            if (k == NULL) {
                PyErr_SetString(PyExc_TypeError, "parameter names must be str");
                return -1;
            }
            for (i = 0; i < N_PARAMS; ++i) {
                if (strcmp(k, g_params[i].name) == 0) {
                    break;
                }
            }
            if (i == N_PARAMS) {
                PyErr_Format(PyExc_TypeError,
                             "unknown parameter %R (bsf.default_params() lists them all)", key);
                return -1;
            }
            if (param_set(out, &g_params[i], value) != 0) {
                return -1;
            }
            st = bsf_params_check(out);
            if (st != BSF_OK) {
                PyErr_Format(g_bsf_error, "parameter %s = %R is out of range for %s: %s", k, value,
                             bsf_method_name(m), bsf_status_str(st));
                return -1;
            }
        }
    }
    st = bsf_params_check(out);
    if (st != BSF_OK) {
        raise_status(st, "parameters");
        return -1;
    }
    return 0;
}

/* ---- results and stats ------------------------------------------------------- */

typedef struct {
    const char *name;
    size_t offset;
} stat_desc_t;

#define STAT(field)                                                                                \
    {                                                                                              \
#field, offsetof(bsf_stats_t, field)                                                       \
    }

/* Every uint32_t counter of bsf_stats_t (stage_ns is handled apart). */
static const stat_desc_t g_stats[] = {
    STAT(n_beams),         STAT(n_valid),        STAT(n_in_features), STAT(n_ctrl),
    STAT(n_features),      STAT(n_keypoints),    STAT(n_unfitted),    STAT(cut),
    STAT(n_cut_keypoints), STAT(n_cut_segments), STAT(n_cut_points),  STAT(time_ns),
    STAT(n_fit_visits),
};
#define N_STATS (sizeof g_stats / sizeof g_stats[0])

static PyObject *stats_to_dict(const bsf_stats_t *s)
{
    PyObject *d = PyDict_New();
    PyObject *stages;
    size_t i;
    if (d == NULL) {
        return NULL;
    }
    for (i = 0; i < N_STATS; ++i) {
        uint32_t v;
        PyObject *o;
        memcpy(&v, (const char *)s + g_stats[i].offset, sizeof v);
        o = PyLong_FromUnsignedLong((unsigned long)v);
        if (o == NULL || PyDict_SetItemString(d, g_stats[i].name, o) != 0) {
            Py_XDECREF(o);
            Py_DECREF(d);
            return NULL;
        }
        Py_DECREF(o);
    }
    stages = PyTuple_New(BSF_STAGE_COUNT);
    if (stages == NULL) {
        Py_DECREF(d);
        return NULL;
    }
    for (i = 0; i < BSF_STAGE_COUNT; ++i) {
        PyObject *o = PyLong_FromUnsignedLong((unsigned long)s->stage_ns[i]);
        if (o == NULL) {
            Py_DECREF(stages);
            Py_DECREF(d);
            return NULL;
        }
        PyTuple_SET_ITEM(stages, (Py_ssize_t)i, o);
    }
    if (PyDict_SetItemString(d, "stage_ns", stages) != 0) {
        Py_DECREF(stages);
        Py_DECREF(d);
        return NULL;
    }
    Py_DECREF(stages);
    return d;
}

static int stats_from_dict(PyObject *d, bsf_stats_t *s)
{
    size_t i;
    memset(s, 0, sizeof *s);
    if (!PyDict_Check(d)) {
        PyErr_SetString(PyExc_TypeError, "stats must be a dict");
        return -1;
    }
    for (i = 0; i < N_STATS; ++i) {
        PyObject *o = PyDict_GetItemString(d, g_stats[i].name); /* borrowed */
        unsigned long v;
        uint32_t v32;
        if (o == NULL || o == Py_None) {
            continue;
        }
        v = PyLong_AsUnsignedLong(o);
        if (v == (unsigned long)-1 && PyErr_Occurred()) {
            PyErr_Format(g_bsf_error, "stats %s must be an integer in 0..4294967295",
                         g_stats[i].name);
            return -1;
        }
        if (v > 0xFFFFFFFFul) {
            PyErr_Format(g_bsf_error, "stats %s = %lu does not fit in 32 bits", g_stats[i].name, v);
            return -1;
        }
        v32 = (uint32_t)v;
        memcpy((char *)s + g_stats[i].offset, &v32, sizeof v32);
    }
    return 0;
}

/* (features, ctrl bytes [float32 x,y pairs], vertex bytes [uint8], stats dict);
 * a feature is (first_beam, last_beam, n_points, kind, e_curve, ctrl_first, n_ctrl). */
static PyObject *result_to_tuple(const bsf_result_t *r)
{
    PyObject *feats = PyList_New((Py_ssize_t)r->n_features);
    PyObject *ctrl = NULL, *vertex = NULL, *stats = NULL;
    size_t i;
    if (feats == NULL) {
        return NULL;
    }
    for (i = 0; i < r->n_features; ++i) {
        const bsf_feature_t *f = &r->features[i];
        PyObject *t =
            Py_BuildValue("(iiiidii)", (int)f->first_beam, (int)f->last_beam, (int)f->n_points,
                          (int)f->kind, (double)f->e_curve, (int)f->ctrl_first, (int)f->n_ctrl);
        if (t == NULL) {
            Py_DECREF(feats);
            return NULL;
        }
        PyList_SET_ITEM(feats, (Py_ssize_t)i, t);
    }
    ctrl = PyBytes_FromStringAndSize(NULL, (Py_ssize_t)r->n_ctrl * 2 * (Py_ssize_t)sizeof(float));
    vertex = PyBytes_FromStringAndSize((const char *)r->ctrl_is_vertex, (Py_ssize_t)r->n_ctrl);
    stats = stats_to_dict(&r->stats);
    if (ctrl == NULL || vertex == NULL || stats == NULL) {
        Py_DECREF(feats);
        Py_XDECREF(ctrl);
        Py_XDECREF(vertex);
        Py_XDECREF(stats);
        return NULL;
    }
    {
        float *dst = (float *)PyBytes_AS_STRING(ctrl);
        for (i = 0; i < r->n_ctrl; ++i) {
            dst[2 * i] = r->ctrl[i].x;
            dst[2 * i + 1] = r->ctrl[i].y;
        }
    }
    return Py_BuildValue("(NNNN)", feats, ctrl, vertex, stats);
}

/* Read a contiguous buffer of `itemsize`-byte items with struct format fmt. */
static int get_buffer(PyObject *obj, Py_buffer *view, const char *fmt, Py_ssize_t itemsize,
                      const char *what)
{
    if (PyObject_GetBuffer(obj, view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) != 0) {
        return -1;
    }
    if (view->itemsize != itemsize ||
        (view->format != NULL && strcmp(view->format, fmt) != 0 &&
         !(view->format[0] == '<' && strcmp(view->format + 1, fmt) == 0) &&
         !(view->format[0] == '=' && strcmp(view->format + 1, fmt) == 0))) {
        PyErr_Format(PyExc_TypeError, "%s must hold %s items (struct format '%s'), got '%s'", what,
                     strcmp(fmt, "f") == 0 ? "float32" : "uint8", fmt,
                     view->format ? view->format : "B");
        PyBuffer_Release(view);
        return -1;
    }
    return 0;
}

/* Fill *r from the tuple layout of result_to_tuple (ctrl_first is recomputed
 * as the running sum when the features are given as a plain sequence). */
static int result_from_tuple(PyObject *tup, bsf_result_t *r)
{
    PyObject *feats, *ctrl_obj, *vertex_obj, *stats_obj;
    Py_buffer ctrl, vertex;
    Py_ssize_t nf, nc, i;
    if (!PyArg_ParseTuple(tup, "OOOO", &feats, &ctrl_obj, &vertex_obj, &stats_obj)) {
        return -1;
    }
    memset(r, 0, sizeof *r);
    feats = PySequence_Fast(feats, "features must be a sequence");
    if (feats == NULL) {
        return -1;
    }
    nf = PySequence_Fast_GET_SIZE(feats);
    if (nf > (Py_ssize_t)BSF_MAX_SEGMENTS) {
        Py_DECREF(feats);
        PyErr_Format(g_bsf_error, "%zd features is more than this build's BSF_MAX_SEGMENTS (%d)",
                     nf, (int)BSF_MAX_SEGMENTS);
        return -1;
    }
    if (get_buffer(ctrl_obj, &ctrl, "f", 4, "control points") != 0) {
        Py_DECREF(feats);
        return -1;
    }
    if (get_buffer(vertex_obj, &vertex, "B", 1, "vertex flags") != 0) {
        PyBuffer_Release(&ctrl);
        Py_DECREF(feats);
        return -1;
    }
    nc = ctrl.len / 8;
    if (ctrl.len % 8 != 0 || vertex.len != nc) {
        PyErr_Format(g_bsf_error,
                     "control points (%zd floats) and vertex flags (%zd) do not match: "
                     "need 2 floats per flag",
                     ctrl.len / 4, vertex.len);
        goto fail;
    }
    if (nc > (Py_ssize_t)BSF_MAX_CTRL_POINTS) {
        PyErr_Format(g_bsf_error,
                     "%zd control points is more than this build's BSF_MAX_CTRL_POINTS (%d)", nc,
                     (int)BSF_MAX_CTRL_POINTS);
        goto fail;
    }
    for (i = 0; i < nc; ++i) {
        const float *src = (const float *)ctrl.buf;
        r->ctrl[i].x = src[2 * i];
        r->ctrl[i].y = src[2 * i + 1];
        r->ctrl_is_vertex[i] = ((const uint8_t *)vertex.buf)[i] ? 1u : 0u;
    }
    r->n_ctrl = (uint16_t)nc;
    for (i = 0; i < nf; ++i) {
        int first, last, npts, kind, cfirst, nctrl;
        double e;
        PyObject *f = PySequence_Fast_GET_ITEM(feats, i);
        if (!PyArg_ParseTuple(f, "iiiidii", &first, &last, &npts, &kind, &e, &cfirst, &nctrl)) {
            goto fail;
        }
        if (first < 0 || first > 65535 || last < 0 || last > 65535 || npts < 0 || npts > 65535 ||
            kind < 0 || kind > 255 || cfirst < 0 || cfirst > 65535 || nctrl < 0 || nctrl > 255) {
            PyErr_Format(g_bsf_error, "feature %zd: a field is out of its range", i);
            goto fail;
        }
        if ((Py_ssize_t)cfirst + nctrl > nc) {
            PyErr_Format(g_bsf_error, "feature %zd: control points %d..%d outside the %zd given", i,
                         cfirst, cfirst + nctrl - 1, nc);
            goto fail;
        }
        if (!isfinite(e)) {
            PyErr_Format(g_bsf_error, "feature %zd: E_curve is not finite", i);
            goto fail;
        }
        r->features[i].first_beam = (uint16_t)first;
        r->features[i].last_beam = (uint16_t)last;
        r->features[i].n_points = (uint16_t)npts;
        r->features[i].kind = (uint8_t)kind;
        r->features[i].e_curve = (float)e;
        r->features[i].ctrl_first = (uint16_t)cfirst;
        r->features[i].n_ctrl = (uint8_t)nctrl;
    }
    r->n_features = (uint16_t)nf;
    PyBuffer_Release(&ctrl);
    PyBuffer_Release(&vertex);
    Py_DECREF(feats);
    return stats_from_dict(stats_obj, &r->stats);
fail:
    PyBuffer_Release(&ctrl);
    PyBuffer_Release(&vertex);
    Py_DECREF(feats);
    return -1;
}

/* ---- Extractor ------------------------------------------------------------------ */

typedef struct {
    PyObject_HEAD bsf_extractor_t *ex;
    bsf_result_t *res;
    int busy;
} ExtractorObject;

static void Extractor_dealloc(ExtractorObject *self)
{
    PyMem_RawFree(self->ex);
    PyMem_RawFree(self->res);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static int Extractor_init(ExtractorObject *self, PyObject *args, PyObject *kwds)
{
    /* char arrays, not literals: the kwlist of the C API is char *[] */
    static char kw_method[] = "method", kw_params[] = "params", kw_timing[] = "timing";
    static char *kwlist[] = {kw_method, kw_params, kw_timing, NULL};
    PyObject *method = NULL, *params = NULL;
    int timing = 1;
    bsf_params_t p;
    bsf_status_t st;
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "U|Op", kwlist, &method, &params, &timing)) {
        return -1;
    }
    if (self->busy) {
        /* another thread is inside bsf_extract on this extractor (without
         * the GIL): re-initialising it now would change its state mid-scan */
        PyErr_SetString(PyExc_RuntimeError, "this Extractor is already running in another thread");
        return -1;
    }
    if (params_build(method, params, &p) != 0) {
        return -1;
    }
    if (timing) {
        p.clock = bsf_port_clock_monotonic_ns;
        p.clock_user = NULL;
        p.clock_hz = 1000000000u;
    }
    if (self->ex == NULL) {
        self->ex = (bsf_extractor_t *)PyMem_RawCalloc(1, sizeof *self->ex);
        self->res = (bsf_result_t *)PyMem_RawCalloc(1, sizeof *self->res);
        if (self->ex == NULL || self->res == NULL) {
            PyErr_NoMemory();
            return -1;
        }
    }
    st = bsf_extractor_init(self->ex, &p);
    if (st != BSF_OK) {
        raise_status(st, "cannot initialise the extractor");
        return -1;
    }
    return 0;
}

static PyObject *Extractor_extract(ExtractorObject *self, PyObject *args)
{
    PyObject *ranges_obj;
    Py_buffer ranges;
    double angle_min, angle_inc, range_min, range_max;
    bsf_scan_t scan;
    bsf_status_t st;
    if (self->ex == NULL) {
        PyErr_SetString(PyExc_RuntimeError, "Extractor not initialised");
        return NULL;
    }
    if (!PyArg_ParseTuple(args, "Odddd", &ranges_obj, &angle_min, &angle_inc, &range_min,
                          &range_max)) {
        return NULL;
    }
    if (get_buffer(ranges_obj, &ranges, "f", 4, "ranges") != 0) {
        return NULL;
    }
    if (ranges.ndim > 1) {
        PyBuffer_Release(&ranges);
        PyErr_SetString(g_bsf_error, "ranges must be one-dimensional");
        return NULL;
    }
    if (ranges.len / 4 > (Py_ssize_t)BSF_MAX_POINTS) {
        const Py_ssize_t n = ranges.len / 4;
        PyBuffer_Release(&ranges);
        PyErr_Format(g_bsf_error,
                     "%zd beams is more than this build's BSF_MAX_POINTS (%d): "
                     "rebuild with a larger cap (BSF_PY_MAX_POINTS)",
                     n, (int)BSF_MAX_POINTS);
        return NULL;
    }
    if (self->busy) {
        PyBuffer_Release(&ranges);
        PyErr_SetString(PyExc_RuntimeError, "this Extractor is already running in another thread");
        return NULL;
    }
    scan.ranges = (const float *)ranges.buf;
    scan.count = (size_t)(ranges.len / 4);
    scan.angle_min = (float)angle_min;
    scan.angle_increment = (float)angle_inc;
    scan.range_min = (float)range_min;
    scan.range_max = (float)range_max;
    self->busy = 1;
    Py_BEGIN_ALLOW_THREADS st = bsf_extract(self->ex, &scan, self->res);
    Py_END_ALLOW_THREADS self->busy = 0;
    PyBuffer_Release(&ranges);
    /* BSF_OK_CUT is a result: what fits the caps, stats.cut says what was left out */
    if (st < 0) {
        return raise_status(st, "extraction failed");
    }
    return result_to_tuple(self->res);
}

static PyObject *Extractor_get_params(ExtractorObject *self, void *closure)
{
    (void)closure;
    if (self->ex == NULL) {
        PyErr_SetString(PyExc_RuntimeError, "Extractor not initialised");
        return NULL;
    }
    return params_to_dict(&self->ex->params);
}

static PyMethodDef Extractor_methods[] = {
    {"extract", (PyCFunction)Extractor_extract, METH_VARARGS,
     "extract(ranges_float32, angle_min, angle_increment, range_min, range_max) -> result tuple"},
    {NULL, NULL, 0, NULL}};

static PyGetSetDef Extractor_getset[] = {
    {"params", (getter)Extractor_get_params, NULL, "effective parameters (dict)", NULL},
    {NULL, NULL, NULL, NULL, NULL}};

static PyTypeObject ExtractorType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "bsf._core.Extractor",
    .tp_basicsize = sizeof(ExtractorObject),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "Extractor(method, params=None, timing=True): bsf_extractor_t owned by Python",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)Extractor_init,
    .tp_dealloc = (destructor)Extractor_dealloc,
    .tp_methods = Extractor_methods,
    .tp_getset = Extractor_getset,
};

/* ---- Decoder --------------------------------------------------------------------- */

typedef struct {
    PyObject_HEAD bsf_decoder_t *dec;
    bsf_frame_t *frame;
    size_t since_frame; /* bytes consumed since the last delivered frame */
} DecoderObject;

static void Decoder_dealloc(DecoderObject *self)
{
    PyMem_RawFree(self->dec);
    PyMem_RawFree(self->frame);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static int Decoder_init(DecoderObject *self, PyObject *args, PyObject *kwds)
{
    static char *kwlist[] = {NULL};
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "", kwlist)) {
        return -1;
    }
    if (self->dec == NULL) {
        self->dec = (bsf_decoder_t *)PyMem_RawCalloc(1, sizeof *self->dec);
        self->frame = (bsf_frame_t *)PyMem_RawCalloc(1, sizeof *self->frame);
        if (self->dec == NULL || self->frame == NULL) {
            PyErr_NoMemory();
            return -1;
        }
    }
    bsf_decoder_init(self->dec);
    self->since_frame = 0;
    return 0;
}

#ifdef BSF_FRAME_TYPE_METADATA
/* bsf_metadata_t as a dict (format version 2). */
static PyObject *metadata_to_dict(const bsf_metadata_t *m)
{
    PyObject *origin, *source;
    if (m->has_time_origin) {
        origin = PyLong_FromLongLong((long long)m->time_origin_us);
    } else {
        origin = Py_None;
        Py_INCREF(origin);
    }
    if (m->source_len > 0u) {
        source = PyUnicode_DecodeUTF8(m->source, (Py_ssize_t)m->source_len, "replace");
    } else {
        source = Py_None;
        Py_INCREF(source);
    }
    if (origin == NULL || source == NULL) {
        Py_XDECREF(origin);
        Py_XDECREF(source);
        return NULL;
    }
    return Py_BuildValue(
        "{s(iii)sisdsds{sksksksksk}sksdsdsdsdsNsN}", "lib_version", (int)m->lib_version_major,
        (int)m->lib_version_minor, (int)m->lib_version_patch, "method_id", (int)m->method,
        "target_rms", (double)m->target_rms, "quant_step", (double)m->quant_step, "caps", "points",
        (unsigned long)m->max_points, "keypoints", (unsigned long)m->max_keypoints, "segments",
        (unsigned long)m->max_segments, "ctrl_per_feature", (unsigned long)m->max_ctrl_per_feature,
        "ctrl_points", (unsigned long)m->max_ctrl_points, "n_beams", (unsigned long)m->n_beams,
        "angle_min", (double)m->angle_min, "angle_increment", (double)m->angle_increment,
        "range_min", (double)m->range_min, "range_max", (double)m->range_max, "time_origin_us",
        origin, "source", source);
}
#endif

/* ("features", version, type, seq, timestamp_ms, pose|None, quant_step,
 *  time_us, result, geometry|None), ("metadata", version, type, dict) or
 *  ("other", version, type) for a type this layer does not convert. */
static PyObject *frame_to_tuple(const bsf_frame_t *f)
{
    PyObject *pose, *res, *geometry;
#ifdef BSF_FRAME_TYPE_METADATA
    if (f->type == BSF_FRAME_TYPE_METADATA) {
        return Py_BuildValue("(siiN)", "metadata", (int)f->version, (int)f->type,
                             metadata_to_dict(&f->metadata));
    }
#endif
#ifdef BSF_FRAME_TYPE_MAP
    if (f->type == BSF_FRAME_TYPE_MAP) {
        /* the checked payload, for a MapReceiver */
        return Py_BuildValue("(siiky#)", "map", (int)f->version, (int)f->type,
                             (unsigned long)f->seq, (const char *)f->payload,
                             (Py_ssize_t)f->payload_len);
    }
#endif
    if (f->type != BSF_FRAME_TYPE_FEATURES) {
        return Py_BuildValue("(sii)", "other", (int)f->version, (int)f->type);
    }
#ifdef BSF_FRAME_TYPE_METADATA
    if (f->has_geometry) {
        geometry = Py_BuildValue("(dd)", (double)f->angle_min, (double)f->angle_increment);
        if (geometry == NULL) {
            return NULL;
        }
    } else
#endif
    {
        geometry = Py_None;
        Py_INCREF(geometry);
    }
    if (f->has_pose) {
        pose = Py_BuildValue("(ddd)", (double)f->pose.x, (double)f->pose.y, (double)f->pose.theta);
    } else {
        pose = Py_None;
        Py_INCREF(pose);
    }
    res = result_to_tuple(&f->result);
    if (pose == NULL || res == NULL) {
        Py_XDECREF(pose);
        Py_XDECREF(res);
        Py_DECREF(geometry);
        return NULL;
    }
    return Py_BuildValue("(siikKNdkNN)", "features", (int)f->version, (int)f->type,
                         (unsigned long)f->seq, (unsigned long long)f->timestamp_ms, pose,
                         (double)f->quant_step, (unsigned long)f->time_us, res, geometry);
}

static PyObject *decoder_run(DecoderObject *self, const uint8_t *data, size_t len)
{
    PyObject *out = PyList_New(0);
    size_t off = 0;
    if (out == NULL) {
        return NULL;
    }
    while (off < len) {
        size_t used = 0;
        const int r = bsf_decoder_feed(self->dec, data + off, len - off, &used, self->frame);
        if (r < 0) {
            Py_DECREF(out);
            return raise_status((bsf_status_t)r, "decoder");
        }
        off += used;
        self->since_frame += used;
        if (r > 0) { /* a frame delivered (the return value is its type from format 2 on) */
            /* (frame, its size on the wire counted like `bsf decode`: every
             * byte since the previous frame, skipped ones included) */
            PyObject *t =
                Py_BuildValue("(Nn)", frame_to_tuple(self->frame), (Py_ssize_t)self->since_frame);
            self->since_frame = 0;
            if (list_append_new(out, t) != 0) {
                Py_DECREF(out);
                return NULL;
            }
        } else if (used == 0) {
            break;
        }
    }
    return out;
}

static PyObject *Decoder_feed(DecoderObject *self, PyObject *arg)
{
    Py_buffer view;
    PyObject *out;
    if (self->dec == NULL) {
        PyErr_SetString(PyExc_RuntimeError, "Decoder not initialised");
        return NULL;
    }
    if (PyObject_GetBuffer(arg, &view, PyBUF_C_CONTIGUOUS) != 0) {
        return NULL;
    }
    out = decoder_run(self, (const uint8_t *)view.buf, (size_t)view.len);
    PyBuffer_Release(&view);
    return out;
}

/* End of stream: a frame complete but for its delimiter is still delivered. */
static PyObject *Decoder_finish(DecoderObject *self, PyObject *unused)
{
    static const uint8_t zero = 0u;
    (void)unused;
    if (self->dec == NULL) {
        PyErr_SetString(PyExc_RuntimeError, "Decoder not initialised");
        return NULL;
    }
    return decoder_run(self, &zero, 1u);
}

static PyObject *Decoder_get_counters(DecoderObject *self, void *closure)
{
    const bsf_decoder_stats_t *s;
    (void)closure;
    if (self->dec == NULL) {
        PyErr_SetString(PyExc_RuntimeError, "Decoder not initialised");
        return NULL;
    }
    s = &self->dec->stats;
    {
        PyObject *d = Py_BuildValue(
            "{sksksksksksksk}", "frames_ok", (unsigned long)s->frames_ok, "bad_crc",
            (unsigned long)s->bad_crc, "malformed", (unsigned long)s->malformed,
            "unsupported_version", (unsigned long)s->unsupported_version, "unknown_type",
            (unsigned long)s->unknown_type, "oversize", (unsigned long)s->oversize, "bytes_skipped",
            (unsigned long)s->bytes_skipped);
#ifdef BSF_FRAME_TYPE_METADATA
        if (d != NULL) {
            PyObject *v = PyLong_FromUnsignedLong((unsigned long)s->metadata);
            if (v == NULL || PyDict_SetItemString(d, "metadata", v) != 0) {
                Py_XDECREF(v);
                Py_DECREF(d);
                return NULL;
            }
            Py_DECREF(v);
        }
#endif
        return d;
    }
}

static PyMethodDef Decoder_methods[] = {
    {"feed", (PyCFunction)Decoder_feed, METH_O, "feed(bytes) -> list of (frame tuple, bytes)"},
    {"finish", (PyCFunction)Decoder_finish, METH_NOARGS,
     "end of stream: deliver a last frame that lacks only its delimiter"},
    {NULL, NULL, 0, NULL}};

static PyGetSetDef Decoder_getset[] = {
    {"counters", (getter)Decoder_get_counters, NULL, "decoder counters (dict)", NULL},
    {NULL, NULL, NULL, NULL, NULL}};

static PyTypeObject DecoderType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "bsf._core.Decoder",
    .tp_basicsize = sizeof(DecoderObject),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "Decoder(): bsf_decoder_t owned by Python",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)Decoder_init,
    .tp_dealloc = (destructor)Decoder_dealloc,
    .tp_methods = Decoder_methods,
    .tp_getset = Decoder_getset,
};

#ifdef BSF_FRAME_TYPE_MAP
/* ---- Map receiver (bsf_map_rx_t): the map a map stream rebuilds ------------------ */

typedef struct {
    PyObject_HEAD bsf_map_rx_t *rx;
    bsf_point_t *ctrl; /* scratch: one feature's points */
    uint8_t *vtx;
} MapReceiverObject;

static void MapReceiver_dealloc(MapReceiverObject *self)
{
    PyMem_Free(self->rx);
    PyMem_Free(self->ctrl);
    PyMem_Free(self->vtx);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static int MapReceiver_init(MapReceiverObject *self, PyObject *args, PyObject *kwds)
{
    static char *kwlist[] = {NULL};
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "", kwlist)) {
        return -1;
    }
    if (self->rx == NULL) {
        self->rx = (bsf_map_rx_t *)PyMem_Malloc(sizeof(bsf_map_rx_t));
        self->ctrl = (bsf_point_t *)PyMem_Malloc(BSF_MAP_RX_MAX_CTRL * sizeof(bsf_point_t));
        self->vtx = (uint8_t *)PyMem_Malloc(BSF_MAP_RX_MAX_CTRL);
        if (self->rx == NULL || self->ctrl == NULL || self->vtx == NULL) {
            PyErr_NoMemory();
            return -1;
        }
    }
    bsf_map_rx_init(self->rx);
    return 0;
}

static int map_rx_ready(const MapReceiverObject *self)
{
    if (self->rx == NULL) {
        PyErr_SetString(PyExc_RuntimeError, "MapReceiver not initialised");
        return 0;
    }
    return 1;
}

/* A new empty list for a method that lists the receiver's features; NULL with
 * an exception when the receiver is not initialised or memory is short. */
static PyObject *map_rx_new_list(const MapReceiverObject *self)
{
    return map_rx_ready(self) ? PyList_New(0) : NULL;
}

/* apply(payload) -> records skipped; BsfError when the payload is refused. */
static PyObject *MapReceiver_apply(MapReceiverObject *self, PyObject *arg)
{
    Py_buffer view;
    int r;
    if (!map_rx_ready(self)) {
        return NULL;
    }
    if (PyObject_GetBuffer(arg, &view, PyBUF_C_CONTIGUOUS) != 0) {
        return NULL;
    }
    r = bsf_map_rx_apply(self->rx, (const uint8_t *)view.buf, (size_t)view.len);
    PyBuffer_Release(&view);
    if (r < 0) {
        return raise_status((bsf_status_t)r, "map frame refused");
    }
    return PyLong_FromLong((long)r);
}

/* features() -> [(id, ctrl bytes (float32 x, y pairs), vertex bytes, stale)] */
static PyObject *MapReceiver_features(MapReceiverObject *self, PyObject *unused)
{
    PyObject *out = map_rx_new_list(self);
    uint32_t id, limit;
    (void)unused;
    if (out == NULL) {
        return NULL;
    }
    limit = bsf_map_rx_id_limit(self->rx);
    for (id = 0; id < limit; ++id) {
        uint8_t stale = 0;
        const int n = bsf_map_rx_feature_ctrl(self->rx, id, self->ctrl, self->vtx,
                                              BSF_MAP_RX_MAX_CTRL, &stale);
        PyObject *t;
        if (n <= 0) {
            continue;
        }
        if (n > (int)BSF_MAP_RX_MAX_CTRL) {
            Py_DECREF(out);
            PyErr_SetString(g_bsf_error,
                            "a map feature has more control points than the receiver holds");
            return NULL;
        }
        t = Py_BuildValue("(ky#y#O)", (unsigned long)id, (const char *)self->ctrl,
                          (Py_ssize_t)((size_t)n * sizeof(bsf_point_t)), (const char *)self->vtx,
                          (Py_ssize_t)n, stale ? Py_True : Py_False);
        if (list_append_new(out, t) != 0) {
            Py_DECREF(out);
            return NULL;
        }
    }
    return out;
}

/* note_loss(): the link dropped a frame (bsf_map_rx_note_loss). */
static PyObject *MapReceiver_note_loss(MapReceiverObject *self, PyObject *unused)
{
    (void)unused;
    if (!map_rx_ready(self)) {
        return NULL;
    }
    bsf_map_rx_note_loss(self->rx);
    Py_RETURN_NONE;
}

/* missing() -> [id]: ids below the id limit that were sent but never received. */
static PyObject *MapReceiver_missing(MapReceiverObject *self, PyObject *unused)
{
    PyObject *out = map_rx_new_list(self);
    uint32_t id, limit;
    (void)unused;
    if (out == NULL) {
        return NULL;
    }
    limit = bsf_map_rx_id_limit(self->rx);
    for (id = 0; id < limit; ++id) {
        if (bsf_map_rx_feature_state(self->rx, id) == BSF_MAP_RX_MISSING) {
            PyObject *v = PyLong_FromUnsignedLong((unsigned long)id);
            if (list_append_new(out, v) != 0) {
                Py_DECREF(out);
                return NULL;
            }
        }
    }
    return out;
}

/* more_missing() -> bool: ids past the largest seen may have been missed. */
static PyObject *MapReceiver_more_missing(MapReceiverObject *self, PyObject *unused)
{
    (void)unused;
    if (!map_rx_ready(self)) {
        return NULL;
    }
    return PyBool_FromLong(bsf_map_rx_feature_state(self->rx, bsf_map_rx_id_limit(self->rx)) ==
                           BSF_MAP_RX_MISSING);
}

static PyObject *MapReceiver_get_pose(MapReceiverObject *self, void *closure)
{
    (void)closure;
    if (!map_rx_ready(self)) {
        return NULL;
    }
    if (!self->rx->has_pose) {
        Py_RETURN_NONE;
    }
    return Py_BuildValue("(ddd)", (double)self->rx->pose.x, (double)self->rx->pose.y,
                         (double)self->rx->pose.theta);
}

static PyObject *MapReceiver_get_counters(MapReceiverObject *self, void *closure)
{
    const bsf_map_rx_stats_t *s;
    (void)closure;
    if (!map_rx_ready(self)) {
        return NULL;
    }
    s = &self->rx->stats;
    return Py_BuildValue("{sksksksksksk}", "frames", (unsigned long)s->frames, "frames_missed",
                         (unsigned long)s->frames_missed, "records", (unsigned long)s->records,
                         "records_skipped", (unsigned long)s->records_skipped, "snapshots",
                         (unsigned long)s->snapshots, "poses", (unsigned long)s->poses);
}

static PyMethodDef MapReceiver_methods[] = {
    {"apply", (PyCFunction)MapReceiver_apply, METH_O,
     "apply(payload) -> records skipped (a map frame's payload)"},
    {"features", (PyCFunction)MapReceiver_features, METH_NOARGS,
     "features() -> list of (id, float32 x/y bytes, vertex flag bytes, stale)"},
    {"note_loss", (PyCFunction)MapReceiver_note_loss, METH_NOARGS,
     "note_loss(): the link dropped a frame; every feature is unconfirmed until the next map "
     "frame"},
    {"missing", (PyCFunction)MapReceiver_missing, METH_NOARGS,
     "missing() -> ids sent by the robot but never received"},
    {"more_missing", (PyCFunction)MapReceiver_more_missing, METH_NOARGS,
     "more_missing() -> True when ids past the largest seen may have been missed"},
    {NULL, NULL, 0, NULL}};

static PyGetSetDef MapReceiver_getset[] = {
    {"pose", (getter)MapReceiver_get_pose, NULL, "last pose record (x, y, theta) or None", NULL},
    {"counters", (getter)MapReceiver_get_counters, NULL, "receiver counters (dict)", NULL},
    {NULL, NULL, NULL, NULL, NULL}};

static PyTypeObject MapReceiverType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "bsf._core.MapReceiver",
    .tp_basicsize = sizeof(MapReceiverObject),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "MapReceiver(): bsf_map_rx_t owned by Python",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)MapReceiver_init,
    .tp_dealloc = (destructor)MapReceiver_dealloc,
    .tp_methods = MapReceiver_methods,
    .tp_getset = MapReceiver_getset,
};
#endif

/* ---- CARMEN reader (the host tool's reader, so geometry matches `bsf extract`) ------ */

typedef struct {
    PyObject_HEAD carmen_reader_t *rd;
} CarmenObject;

static void Carmen_close_reader(CarmenObject *self)
{
    if (self->rd != NULL) {
        carmen_close(self->rd);
        self->rd = NULL;
    }
}

static void Carmen_dealloc(CarmenObject *self)
{
    Carmen_close_reader(self);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static int Carmen_init(CarmenObject *self, PyObject *args, PyObject *kwds)
{
    static char kw_path[] = "path";
    static char *kwlist[] = {kw_path, NULL};
    PyObject *path = NULL;
    const char *p;
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "O&", kwlist, PyUnicode_FSConverter, &path)) {
        return -1;
    }
    Carmen_close_reader(self);
    p = PyBytes_AS_STRING(path);
    errno = 0;
    self->rd = carmen_open(p, stderr);
    if (self->rd == NULL) {
        PyErr_SetFromErrnoWithFilenameObject(PyExc_OSError, path);
        Py_DECREF(path);
        return -1;
    }
    Py_DECREF(path);
    return 0;
}

static PyObject *Carmen_next(CarmenObject *self)
{
    carmen_scan_t s;
    int r;
    PyObject *ranges;
    if (self->rd == NULL) {
        return NULL; /* closed: StopIteration */
    }
    fflush(stderr);
    r = carmen_next(self->rd, &s);
    if (r == 0) {
        return NULL;
    }
    if (r < 0) {
        PyErr_SetString(PyExc_OSError, "read error in the CARMEN log (reported above)");
        return NULL;
    }
    ranges =
        PyBytes_FromStringAndSize((const char *)s.ranges, (Py_ssize_t)(s.count * sizeof(float)));
    if (ranges == NULL) {
        return NULL;
    }
    return Py_BuildValue("{sNsisdsdsdsds(ddd)s(ddd)sdsk}", "ranges", ranges, "type", (int)s.type,
                         "angle_min", (double)s.angle_min, "angle_increment",
                         (double)s.angle_increment, "max_range", (double)s.max_range,
                         "valid_range_max", (double)carmen_valid_range_max(&s), "laser_pose",
                         s.laser_pose.x, s.laser_pose.y, s.laser_pose.theta, "robot_pose",
                         s.robot_pose.x, s.robot_pose.y, s.robot_pose.theta, "timestamp",
                         s.timestamp, "line", (unsigned long)s.line);
}

static PyObject *Carmen_close(CarmenObject *self, PyObject *unused)
{
    (void)unused;
    Carmen_close_reader(self);
    Py_RETURN_NONE;
}

static PyObject *Carmen_get_malformed(CarmenObject *self, void *closure)
{
    (void)closure;
    if (self->rd == NULL) {
        return PyLong_FromLong(0);
    }
    return PyLong_FromUnsignedLong(carmen_malformed_count(self->rd));
}

static PyObject *Carmen_get_overlong(CarmenObject *self, void *closure)
{
    (void)closure;
    if (self->rd == NULL) {
        return PyLong_FromLong(0);
    }
    return PyLong_FromUnsignedLong(carmen_overlong_count(self->rd));
}

static PyMethodDef Carmen_methods[] = {
    {"close", (PyCFunction)Carmen_close, METH_NOARGS, "close the log"}, {NULL, NULL, 0, NULL}};

static PyGetSetDef Carmen_getset[] = {
    {"malformed", (getter)Carmen_get_malformed, NULL, "malformed laser lines skipped so far", NULL},
    {"overlong", (getter)Carmen_get_overlong, NULL,
     "lines longer than the reader's cap (1 MiB) skipped so far (also counted as malformed)", NULL},
    {NULL, NULL, NULL, NULL, NULL}};

static PyTypeObject CarmenType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "bsf._core.CarmenReader",
    .tp_basicsize = sizeof(CarmenObject),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "CarmenReader(path): iterate over the laser scans of a CARMEN log (plain or gzip)",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)Carmen_init,
    .tp_dealloc = (destructor)Carmen_dealloc,
    .tp_iter = PyObject_SelfIter,
    .tp_iternext = (iternextfunc)Carmen_next,
    .tp_methods = Carmen_methods,
    .tp_getset = Carmen_getset,
};

/* ---- module functions -------------------------------------------------------------- */

/* An integer in 0..max (PyArg_ParseTuple's "k" and "K" wrap silently):
 * 0, or -1 with TypeError (not an integer) or OverflowError set. */
static int unsigned_arg(PyObject *obj, const char *name, unsigned long long max,
                        unsigned long long *out)
{
    PyObject *index = PyNumber_Index(obj);
    PyObject *zero;
    int negative;
    if (index == NULL) {
        return -1;
    }
    zero = PyLong_FromLong(0);
    negative = zero != NULL ? PyObject_RichCompareBool(index, zero, Py_LT) : -1;
    Py_XDECREF(zero);
    *out = negative == 0 ? PyLong_AsUnsignedLongLong(index) : 0u;
    Py_DECREF(index);
    if (negative < 0) {
        return -1;
    }
    if (negative == 1 || (*out == (unsigned long long)-1 && PyErr_Occurred()) || *out > max) {
        PyErr_Clear();
        PyErr_Format(PyExc_OverflowError, "%s = %R is outside 0..%llu", name, obj, max);
        return -1;
    }
    return 0;
}

static PyObject *core_encode(PyObject *mod, PyObject *args)
{
    unsigned long long seq, ts;
    PyObject *pose, *res_tup, *out;
    double quant;
    bsf_frame_info_t info;
    bsf_result_t *res;
    bsf_status_t st;
    size_t len = 0;
    (void)mod;
    PyObject *geometry = Py_None;
    PyObject *seq_obj, *ts_obj;
    if (!PyArg_ParseTuple(args, "OOOdO|O", &seq_obj, &ts_obj, &pose, &quant, &res_tup, &geometry)) {
        return NULL;
    }
    if (unsigned_arg(seq_obj, "seq", 0xFFFFFFFFull, &seq) != 0 ||
        unsigned_arg(ts_obj, "timestamp_ms", 0xFFFFFFFFFFFFFFFFull, &ts) != 0) {
        return NULL;
    }
    bsf_frame_info_init(&info);
    info.seq = (uint32_t)seq;
    info.timestamp_ms = (uint64_t)ts;
    info.quant_step = (float)quant;
    if (pose != Py_None) {
        double x, y, th;
        if (!PyArg_ParseTuple(pose, "ddd", &x, &y, &th)) {
            return NULL;
        }
        info.has_pose = 1u;
        info.pose.x = (float)x;
        info.pose.y = (float)y;
        info.pose.theta = (float)th;
    }
    if (geometry != Py_None) {
#ifdef BSF_FRAME_TYPE_METADATA
        double amin, ainc;
        if (!PyArg_ParseTuple(geometry, "dd", &amin, &ainc)) {
            return NULL;
        }
        info.has_geometry = 1u;
        info.angle_min = (float)amin;
        info.angle_increment = (float)ainc;
#else
        PyErr_SetString(g_bsf_error, "this stream format version cannot carry a frame's geometry");
        return NULL;
#endif
    }
    res = (bsf_result_t *)PyMem_RawMalloc(sizeof *res);
    if (res == NULL) {
        return PyErr_NoMemory();
    }
    if (result_from_tuple(res_tup, res) != 0) {
        PyMem_RawFree(res);
        return NULL;
    }
    st = bsf_frame_encode(&info, res, NULL, 0, &len);
    if (st != BSF_OK) {
        PyMem_RawFree(res);
        return raise_status(st, "cannot encode the frame");
    }
    out = PyBytes_FromStringAndSize(NULL, (Py_ssize_t)len);
    if (out == NULL) {
        PyMem_RawFree(res);
        return NULL;
    }
    st = bsf_frame_encode(&info, res, (uint8_t *)PyBytes_AS_STRING(out), len, &len);
    PyMem_RawFree(res);
    if (st != BSF_OK) {
        Py_DECREF(out);
        return raise_status(st, "cannot encode the frame");
    }
    return out;
}

#ifdef BSF_FRAME_TYPE_METADATA
static int dict_double(PyObject *d, const char *key, double *out)
{
    PyObject *v = PyDict_GetItemString(d, key); /* borrowed */
    if (v == NULL) {
        PyErr_Format(PyExc_KeyError, "metadata needs %s", key);
        return -1;
    }
    *out = PyFloat_AsDouble(v);
    return (*out == -1.0 && PyErr_Occurred()) ? -1 : 0;
}

static int dict_ulong(PyObject *d, const char *key, unsigned long hi, unsigned long *out)
{
    PyObject *v = PyDict_GetItemString(d, key); /* borrowed */
    if (v == NULL) {
        PyErr_Format(PyExc_KeyError, "metadata needs %s", key);
        return -1;
    }
    *out = PyLong_AsUnsignedLong(v);
    if (*out == (unsigned long)-1 && PyErr_Occurred()) {
        return -1;
    }
    if (*out > hi) {
        PyErr_Format(g_bsf_error, "metadata %s = %lu is above %lu", key, *out, hi);
        return -1;
    }
    return 0;
}

/* encode_metadata(dict) -> bytes, the dict of metadata_to_dict (lib_version
 * is always this library's). */
static PyObject *core_encode_metadata(PyObject *mod, PyObject *arg)
{
    bsf_metadata_t m;
    PyObject *caps, *origin, *source, *out;
    double target, step, amin, ainc, rmin, rmax;
    unsigned long method, n_beams, cp, ck, cs, cf, cc;
    size_t len = 0;
    bsf_status_t st;
    (void)mod;
    if (!PyDict_Check(arg)) {
        PyErr_SetString(PyExc_TypeError, "metadata must be a dict");
        return NULL;
    }
    bsf_metadata_init(&m);
    caps = PyDict_GetItemString(arg, "caps");
    if (caps == NULL || !PyDict_Check(caps)) {
        PyErr_SetString(PyExc_KeyError, "metadata needs caps (a dict)");
        return NULL;
    }
    if (dict_ulong(arg, "method_id", 255ul, &method) || dict_double(arg, "target_rms", &target) ||
        dict_double(arg, "quant_step", &step) || dict_ulong(arg, "n_beams", 65535ul, &n_beams) ||
        dict_double(arg, "angle_min", &amin) || dict_double(arg, "angle_increment", &ainc) ||
        dict_double(arg, "range_min", &rmin) || dict_double(arg, "range_max", &rmax) ||
        dict_ulong(caps, "points", 65535ul, &cp) || dict_ulong(caps, "keypoints", 65535ul, &ck) ||
        dict_ulong(caps, "segments", 65535ul, &cs) ||
        dict_ulong(caps, "ctrl_per_feature", 65535ul, &cf) ||
        dict_ulong(caps, "ctrl_points", 65535ul, &cc)) {
        return NULL;
    }
    m.method = (uint8_t)method;
    m.target_rms = (float)target;
    m.quant_step = (float)step;
    m.n_beams = (uint32_t)n_beams;
    m.angle_min = (float)amin;
    m.angle_increment = (float)ainc;
    m.range_min = (float)rmin;
    m.range_max = (float)rmax;
    m.max_points = (uint32_t)cp;
    m.max_keypoints = (uint32_t)ck;
    m.max_segments = (uint32_t)cs;
    m.max_ctrl_per_feature = (uint32_t)cf;
    m.max_ctrl_points = (uint32_t)cc;
    origin = PyDict_GetItemString(arg, "time_origin_us");
    if (origin != NULL && origin != Py_None) {
        int overflow = 0;
        const long long v = PyLong_AsLongLongAndOverflow(origin, &overflow);
        if (v == -1 && PyErr_Occurred()) {
            return NULL;
        }
        if (overflow != 0) {
            PyErr_SetString(g_bsf_error, "metadata time_origin_us does not fit in 64 bits");
            return NULL;
        }
        m.has_time_origin = 1u;
        m.time_origin_us = (int64_t)v;
    }
    source = PyDict_GetItemString(arg, "source");
    if (source != NULL && source != Py_None) {
        Py_ssize_t n = 0;
        const char *u = PyUnicode_Check(source) ? PyUnicode_AsUTF8AndSize(source, &n) : NULL;
        if (u == NULL) {
            if (!PyErr_Occurred()) {
                PyErr_SetString(PyExc_TypeError, "metadata source must be a str");
            }
            return NULL;
        }
        if (n > (Py_ssize_t)BSF_METADATA_SOURCE_MAX) {
            PyErr_Format(g_bsf_error, "metadata source is %zd bytes of UTF-8, at most %d", n,
                         (int)BSF_METADATA_SOURCE_MAX);
            return NULL;
        }
        memcpy(m.source, u, (size_t)n);
        m.source[n] = '\0';
        m.source_len = (uint8_t)n;
    }
    st = bsf_metadata_encode(&m, NULL, 0, &len);
    if (st != BSF_OK) {
        return raise_status(st, "cannot encode the metadata frame");
    }
    out = PyBytes_FromStringAndSize(NULL, (Py_ssize_t)len);
    if (out == NULL) {
        return NULL;
    }
    st = bsf_metadata_encode(&m, (uint8_t *)PyBytes_AS_STRING(out), len, &len);
    if (st != BSF_OK) {
        Py_DECREF(out);
        return raise_status(st, "cannot encode the metadata frame");
    }
    return out;
}

/* bsf_metadata_init() of this build as a dict. */
static PyObject *core_default_metadata(PyObject *mod, PyObject *unused)
{
    bsf_metadata_t m;
    (void)mod;
    (void)unused;
    bsf_metadata_init(&m);
    return metadata_to_dict(&m);
}
#endif

static PyObject *core_bspline_eval(PyObject *mod, PyObject *args)
{
    PyObject *ctrl_obj, *t_obj, *out;
    Py_buffer ctrl, t;
    Py_ssize_t n_ctrl, n_t, i;
    float *dst;
    (void)mod;
    if (!PyArg_ParseTuple(args, "OO", &ctrl_obj, &t_obj)) {
        return NULL;
    }
    if (get_buffer(ctrl_obj, &ctrl, "f", 4, "control points") != 0) {
        return NULL;
    }
    if (get_buffer(t_obj, &t, "f", 4, "parameters") != 0) {
        PyBuffer_Release(&ctrl);
        return NULL;
    }
    n_ctrl = ctrl.len / 8;
    n_t = t.len / 4;
    out = PyBytes_FromStringAndSize(NULL, n_t * 8);
    if (out == NULL) {
        goto done;
    }
    dst = (float *)PyBytes_AS_STRING(out);
    for (i = 0; i < n_t; ++i) {
        bsf_point_t p;
        const bsf_status_t st = bsf_bspline_eval((const bsf_point_t *)ctrl.buf, (size_t)n_ctrl,
                                                 ((const float *)t.buf)[i], &p, NULL, NULL);
        if (st != BSF_OK) {
            Py_CLEAR(out);
            raise_status(st, "cannot evaluate the curve");
            goto done;
        }
        dst[2 * i] = p.x;
        dst[2 * i + 1] = p.y;
    }
done:
    PyBuffer_Release(&ctrl);
    PyBuffer_Release(&t);
    return out;
}

static PyObject *core_default_params(PyObject *mod, PyObject *args)
{
    PyObject *method;
    bsf_params_t p;
    (void)mod;
    if (!PyArg_ParseTuple(args, "U", &method)) {
        return NULL;
    }
    if (params_build(method, NULL, &p) != 0) {
        return NULL;
    }
    return params_to_dict(&p);
}

/* version() -> "MAJOR.MINOR.PATCH" of the compiled library (bsf.__version__). */
static PyObject *core_version(PyObject *mod, PyObject *unused)
{
    (void)mod;
    (void)unused;
    return PyUnicode_FromString(bsf_version());
}

static PyMethodDef core_methods[] = {
    {"version", core_version, METH_NOARGS, "version() -> the C library's version string"},
    {"encode", core_encode, METH_VARARGS,
     "encode(seq, timestamp_ms, pose|None, quant_step, result) -> frame bytes"},
    {"bspline_eval", core_bspline_eval, METH_VARARGS,
     "bspline_eval(ctrl float32 pairs, t float32) -> float32 pairs"},
    {"default_params", core_default_params, METH_VARARGS,
     "default_params(method) -> dict of every parameter"},
#ifdef BSF_FRAME_TYPE_METADATA
    {"encode_metadata", core_encode_metadata, METH_O, "encode_metadata(dict) -> frame bytes"},
    {"default_metadata", core_default_metadata, METH_NOARGS,
     "bsf_metadata_init() of this build as a dict"},
#endif
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef core_module = {PyModuleDef_HEAD_INIT,
                                         "bsf._core",
                                         "The bsf C library, compiled from its own src/.",
                                         -1,
                                         core_methods,
                                         NULL,
                                         NULL,
                                         NULL,
                                         NULL};

PyMODINIT_FUNC PyInit__core(void);

PyMODINIT_FUNC PyInit__core(void)
{
    PyObject *m;
    PyObject *caps;
    if (PyType_Ready(&ExtractorType) < 0 || PyType_Ready(&DecoderType) < 0 ||
        PyType_Ready(&CarmenType) < 0
#ifdef BSF_FRAME_TYPE_MAP
        || PyType_Ready(&MapReceiverType) < 0
#endif
    ) {
        return NULL;
    }
    m = PyModule_Create(&core_module);
    if (m == NULL) {
        return NULL;
    }
    g_bsf_error = PyErr_NewExceptionWithDoc(
        "bsf.BsfError",
        "An error reported by the bsf library (bad input, a cap exceeded, a frame that cannot be "
        "encoded). A ValueError; .status holds the library's status code when there is one.",
        PyExc_ValueError, NULL);
    if (g_bsf_error == NULL || PyModule_AddObject(m, "BsfError", g_bsf_error) != 0) {
        Py_DECREF(m);
        return NULL;
    }
    Py_INCREF(g_bsf_error); /* PyModule_AddObject stole one reference */
    Py_INCREF(&ExtractorType);
    Py_INCREF(&DecoderType);
    Py_INCREF(&CarmenType);
    if (PyModule_AddObject(m, "Extractor", (PyObject *)&ExtractorType) != 0 ||
        PyModule_AddObject(m, "Decoder", (PyObject *)&DecoderType) != 0 ||
        PyModule_AddObject(m, "CarmenReader", (PyObject *)&CarmenType) != 0) {
        Py_DECREF(m);
        return NULL;
    }
#ifdef BSF_FRAME_TYPE_MAP
    Py_INCREF(&MapReceiverType);
    if (PyModule_AddObject(m, "MapReceiver", (PyObject *)&MapReceiverType) != 0) {
        Py_DECREF(&MapReceiverType);
        Py_DECREF(m);
        return NULL;
    }
#endif
    caps = Py_BuildValue("{sisisisisisisi}", "BSF_MAX_POINTS", (int)BSF_MAX_POINTS,
                         "BSF_MAX_KEYPOINTS", (int)BSF_MAX_KEYPOINTS, "BSF_MAX_SEGMENTS",
                         (int)BSF_MAX_SEGMENTS, "BSF_MAX_CTRL_PER_FEATURE",
                         (int)BSF_MAX_CTRL_PER_FEATURE, "BSF_MAX_CTRL_POINTS",
                         (int)BSF_MAX_CTRL_POINTS, "BSF_FRAME_MAX_SIZE", (int)BSF_FRAME_MAX_SIZE,
                         "BSF_FORMAT_VERSION", (int)BSF_FORMAT_VERSION);
    if (caps == NULL || PyModule_AddObject(m, "caps", caps) != 0) {
        Py_XDECREF(caps);
        Py_DECREF(m);
        return NULL;
    }
    if (PyModule_AddIntConstant(m, "FRAME_TYPE_FEATURES", (long)BSF_FRAME_TYPE_FEATURES) != 0 ||
        PyModule_AddObject(m, "QUANT_STEP_DEFAULT",
                           PyFloat_FromDouble((double)BSF_QUANT_STEP_DEFAULT)) != 0 ||
        PyModule_AddObject(m, "QUANT_STEP_MIN", PyFloat_FromDouble((double)BSF_QUANT_STEP_MIN)) !=
            0 ||
        PyModule_AddObject(m, "QUANT_STEP_MAX", PyFloat_FromDouble((double)BSF_QUANT_STEP_MAX)) !=
            0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
