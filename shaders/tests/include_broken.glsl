// Test fixture: included by tests/broken_include.frag; the next function has an error.
float brokenHelper() {
  return UNDECLARED_IN_INCLUDE;
}
