/* placeholder until the scene tests land */
static const rad_test_case tests_scene[] = { { NULL, NULL } };
