#include <cstdio>
int main() { std::puts("mcfbench"); return 0; }
