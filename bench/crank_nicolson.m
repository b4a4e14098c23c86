% crank_nicolson.m -- bench/crank_nicolson.silc's problem in Octave, for
% bench/startup.sh: the same matrices and initial field, and the loop alone
% timed (tic/toc and cputime, Octave's start and the assembly excluded).
% Prints "octave loop WALL_S CPU_S sum(u)".
k = 100; nsteps = 100; dt = 2e-4;
h = 1 / (k + 1); s = dt / (2 * h * h); e = ones(k, 1);
T = spdiags([-e, 2 * e, -e], -1:1, k, k); I = speye(k); L = kron(I, T) + kron(T, I);
A = speye(k * k) + s * L; B = speye(k * k) - s * L;
g = (1:k)' * h; blk = double(g > 0.4 & g < 0.6); u = kron(blk, blk);
c = cputime; tic;
for i = 1:nsteps
  u = A \ (B * u);
end
t = toc; c = cputime - c;
printf('octave loop %.6g %.6g %.16g\n', t, c, sum(u));
