/* A trailing comma in a lights file is named as such, at the comma's line
 * ("t.json: line 2: trailing comma before '}'"), in objects and arrays,
 * with white space or newlines before the closer; other syntax errors keep
 * their line and column. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "helpers.h"

#include <stdio.h>
#include <string.h>

static void expect(const char *text, const char *message)
{
    lx_scene *s = lx_test_new_scene("t");
    assert_int_equal(lx_lights_json_apply_text(s, text, strlen(text), "t.json"), LX_ERR_FORMAT);
    if (!strstr(lx_last_error(), message))
        fail_msg("'%s': got '%s', want '%s'", text, lx_last_error(), message);
    lx_scene_destroy(s);
}

static void trailing_commas(void **state)
{
    (void)state;
    expect("{\"ambient\": [1, 1, 1],\n}", "t.json: line 1: trailing comma before '}'");
    expect("{\"ambient\": [1, 1, 1,]}", "t.json: line 1: trailing comma before ']'");
    expect("{\"lights\": [\n  {\"type\": \"point\",\n   \"intensity\": 1,\n  }]}",
           "t.json: line 3: trailing comma before '}'");
    expect("{\"lights\": [\n  {\"type\": \"point\"},\n\n]}",
           "t.json: line 2: trailing comma before ']'");
    /* not a trailing comma: line and column as before */
    expect("{\"ambient\": [1 1]}", "t.json: line 1, column");
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(trailing_commas)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
