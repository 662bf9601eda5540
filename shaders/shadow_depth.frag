#version 330 core
// Depth only: the depth attachment keeps the nearest surface; no colour is written.
void main() {
}
