/* placeholder until the light tests land */
static const rad_test_case tests_light[] = { { NULL, NULL } };
