/* placeholder until the formfactor tests land */
static const rad_test_case tests_formfactor[] = { { NULL, NULL } };
