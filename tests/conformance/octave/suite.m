# The statement suite that SILC and Octave must print alike
# (tests/conformance/octave/README.md).  Every line is valid in both languages.
x = 3
y = pi
z = 0.031416
w = 0.0031416
a = 31415.9
b = 314.159
k = -0.5
n = -2
big = 1e10
q = 1e-10
A = [1 2; 3 4]
B = [1.5 2.25; -3 4]
C = [100.5 2.25]
D = [0.01 1]
E = [0.001 1]
M = [1 -2]
M2 = [1 - 2]
M3 = [1 , 2
3 4]
N = [NaN 1 Inf]
e = [];
e
v = 1:5
v2 = [0:0.25:1];
v2
r = 10:-3:1
r0 = 5:1
c = size(0:0.1:1, 2)
lastv = max(0:0.1:1)
s = sum(1:100)
t = (1:3)'
u = [1:3; 4:6]
uw = [(1:20) * 2]
S = sparse([1 2 3], [1 2 3], [4 5 6], 3, 3)
S2 = sparse(1:4, 1:4, 2, 4, 4);
nnz(S2)
k2 = 0;
for i = 1:10
  k2 = k2 + i;
end
k2
j = 0;
while j < 7
  j = j + 2;
end
j
if j > 5
  big2 = 1;
else
  big2 = 0;
end
big2
if j < 5, w2 = 1; elseif j == 8, w2 = 2; else, w2 = 3; end
w2
acc = 0;
for col = [1 2; 3 4]
  acc = acc + col' * col;
end
acc
f = 2 * (1:4) + 1
g = (1:4) .^ 2
h = [1 2 3] * [4 5 6]'
abs([-1.5 2])
# subscripts, as Octave writes them (on a variable: a call otherwise)
vv = [10 20 30 40 50];
vv(2)
vv(2:4)
vv(end)
vv(end - 1:end)
vv([1 3 5])
vv(vv > 25)
vv(:)
AA = [1 2 3; 4 5 6; 7 8 10];
AA(2, 3)
AA(:, 2)
AA(2:3, :)
AA(end, end)
AA(5)
AA([1 3])
AA(AA > 5)
AA(1, AA(1, :) > 1)
ww = vv;
ww(2) = 0
ww(ww > 35) = -1
BB = AA;
BB(2, :) = [0 0 0]
BB(:, 1) = 9
m1 = AA(2, :) * AA(:, 2)
1 + 1;
disp(pi)
disp([1 2; 3 4])
format long
p = pi
P = [pi 1]
r3 = 1/3
format short
p = pi
# complex values (issue 31): literals, the imaginary unit, display, parts
zc = 1+2i
zw = 1.5 - 2j
zn = -1i
zq = 1e-3 + 2i
ze = 1e5+1i
zN = 1+NaN*1i
Zc = [1+2i, 3-4i; 5, 6i]
Zd = [1.5+2i; -3.25-0.5i]
Zm = [1e-3+1i, 100]
Zs = sparse([1 2], [1 2], [1+2i, 3], 2, 2)
zr = sqrt(-4)
zl = log(-1)
za = abs(3+4i)
zg = angle(1i)
Zt = [1+2i; 3]'
Zp = [1+2i; 3].'
Zre = real(Zc)
Zim = imag(Zc)
Zcj = conj(Zc)
zx = complex(1, 0)
zi = isreal(zx)
Ar = [4 1; 1 3];
bc = [1+1i; 2-1i];
xr = Ar \ bc
Hc = [2, 1+1i; 1-1i, 3];
yc = Hc \ bc
zd = dot([1i; 2], [1; 1i])
zm = norm([3+4i; 0])
zs = sum([1+2i; 3-1i])
zp = Zc * [1; 1i]
ze2 = Zc .* Zc
clear i j
zu = i
zv = 3*j
# growth by assignment, as Octave grows (zero-filled)
gv = [1 2 3];
gv(5) = 9
ga = [];
ga(3) = 1
gc = [1; 2];
gc(4) = 7
gA = ones(2);
gA(3, 4) = 5
gw = 1:3;
gw(end+1) = 4
gz = 5;
gz(3) = 2
ge = zeros(0, 3);
ge(2) = 1
gr = [1 2 3];
gr([2 6]) = [8 9]
gt = ones(2, 3);
gt(:, 5) = 2
gn(3) = 1
gx = 1;
gx(2, 2) = 1i
format long
zL = 1/3 + 2i/3
ZL = [1+2i, 3.5-4i]
format short
