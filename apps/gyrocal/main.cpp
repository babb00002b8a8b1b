// gyrocal: the command line (INTERFACE.md). Parsing arguments and printing only; no physics here.
#include <cstdio>

int main() {
  std::puts("gyrocal");
  return 0;
}
