#version 330 core
// Vertex stage of user_check.frag (nothing to draw: the program is only compiled).
void main() {
    gl_Position = vec4(0.0, 0.0, 0.0, 1.0);
}
