/*
 * json_same.h — two jansson trees alike value by value: the same types, integers, reals by
 * their bits (json_equal takes -0.0 for 0.0), strings by bytes and length, arrays in order,
 * object members in the same order (jansson keeps insertion order) with the same keys.  Used by
 * jsonread_test.c and the fuzz target (tests/fuzz) to hold codec_json_fast (server/codec/
 * jsonread.c) to json_loadb's tree.
 */
#ifndef SPINMODAL_TESTS_JSON_SAME_H
#define SPINMODAL_TESTS_JSON_SAME_H

#include <jansson.h>
#include <string.h>

static inline int json_same(const json_t *a, const json_t *b)
{
    if (!a || !b || json_typeof(a) != json_typeof(b))
        return 0;
    switch (json_typeof(a)) {
    case JSON_INTEGER:
        return json_integer_value(a) == json_integer_value(b);
    case JSON_REAL: {
        double x = json_real_value(a), y = json_real_value(b);
        return memcmp(&x, &y, sizeof x) == 0;
    }
    case JSON_STRING:
        return json_string_length(a) == json_string_length(b) &&
               memcmp(json_string_value(a), json_string_value(b), json_string_length(a)) == 0;
    case JSON_ARRAY:
        if (json_array_size(a) != json_array_size(b))
            return 0;
        for (size_t i = 0; i < json_array_size(a); i++)
            if (!json_same(json_array_get(a, i), json_array_get(b, i)))
                return 0;
        return 1;
    case JSON_OBJECT: {
        if (json_object_size(a) != json_object_size(b))
            return 0;
        void *ia = json_object_iter((json_t *)a), *ib = json_object_iter((json_t *)b);
        for (; ia && ib; ia = json_object_iter_next((json_t *)a, ia),
                         ib = json_object_iter_next((json_t *)b, ib)) {
            size_t la = json_object_iter_key_len(ia), lb = json_object_iter_key_len(ib);
            if (la != lb || memcmp(json_object_iter_key(ia), json_object_iter_key(ib), la) ||
                !json_same(json_object_iter_value(ia), json_object_iter_value(ib)))
                return 0;
        }
        return !ia && !ib;
    }
    default: /* true, false, null */
        return 1;
    }
}

#endif /* SPINMODAL_TESTS_JSON_SAME_H */
