#include <cstdio>
int main() { std::puts("clothsim: under construction"); return 1; }
